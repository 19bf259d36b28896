//! `strata info`.

use anyhow::Result;
use strata_render::gpu::STRATA_FEATURES;

use crate::args::InfoArgs;

pub fn run(a: &InfoArgs) -> Result<()> {
    let gpu = strata_render::GpuContext::new(&strata_render::GpuOptions {
        adapter: a.gpu.adapter.clone(),
    })?;
    let i = gpu.adapter.get_info();
    if a.json {
        let feats: serde_json::Map<String, serde_json::Value> = STRATA_FEATURES
            .iter()
            .map(|(n, f, _)| (n.to_string(), gpu.has(*f).into()))
            .collect();
        let v = serde_json::json!({
            "adapter": i.name, "backend": format!("{:?}", i.backend), "device_type": format!("{:?}", i.device_type),
            "driver": i.driver, "driver_info": i.driver_info, "features": feats,
            "max_multiview_view_count": gpu.device.limits().max_multiview_view_count,
            "storage_formats": strata_render::passes::SCREEN_FORMATS
                .iter()
                .map(|f| (format!("{f:?}"), strata_render::passes::storable(&gpu, *f).into()))
                .collect::<serde_json::Map<String, serde_json::Value>>(),
            "driver_issue": gpu.driver_issue(),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    println!("adapter      {}", i.name);
    println!("backend      {:?}", i.backend);
    println!("device type  {:?}", i.device_type);
    println!("driver       {} {}", i.driver, i.driver_info);
    println!(
        "multiview    up to {} views",
        gpu.device.limits().max_multiview_view_count
    );
    if let Some(w) = gpu.driver_issue() {
        println!("warning      {w}");
    }
    println!();
    println!("{:<40} {:<8} used for", "feature", "present");
    for (name, f, why) in STRATA_FEATURES {
        println!("{:<40} {:<8} {}", name, if gpu.has(*f) { "yes" } else { "no" }, why);
    }
    println!();
    println!("{:<40} {:<8} used for", "storage texture format", "present");
    for f in strata_render::passes::SCREEN_FORMATS {
        println!(
            "{:<40} {:<8} compute forms of the screen passes (`*-kernel` settings)",
            format!("{f:?}"),
            if strata_render::passes::storable(&gpu, *f) {
                "yes"
            } else {
                "no"
            }
        );
    }
    Ok(())
}
