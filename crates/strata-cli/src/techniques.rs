//! `strata techniques`: the registry as a table or JSON (what a viewer reads).

use anyhow::Result;
use strata_render::technique::{registry, Range, Technique};
use strata_render::RenderSettings;

use crate::args::TechniquesArgs;

/// Settings are f32: show the shortest decimal that is the same f32 (0.85, not 0.8500000238).
fn tidy(v: f64) -> f64 {
    (v as f32).to_string().parse().unwrap_or(v)
}

fn range_json(r: Range) -> serde_json::Value {
    let (min, max, min_inclusive, max_inclusive) = match r {
        Range::Closed(a, b) => (Some(a), Some(b), true, true),
        Range::HalfOpen(a, b) => (Some(a), Some(b), true, false),
        Range::AtLeast(a) => (Some(a), None, true, false),
        Range::Above(a) => (Some(a), None, false, false),
        Range::OffOr(_, b) => (Some(0.0), Some(b), true, true),
    };
    // OffOr: the values strictly between 0 and `off_or_from` are out of range
    let off_or_from = match r {
        Range::OffOr(a, _) => Some(a),
        _ => None,
    };
    serde_json::json!({
        "text": r.to_string(), "min": min, "max": max,
        "min_inclusive": min_inclusive, "max_inclusive": max_inclusive,
        "off_or_from": off_or_from,
    })
}

/// One technique with its settings' defaults (`null`: taken from the scene).
pub fn technique_json(t: &Technique) -> Result<serde_json::Value> {
    let defaults = t.settings(&RenderSettings::default(), None)?;
    let settings: Vec<_> = t
        .setting_list()
        .map(|i| {
            serde_json::json!({
                "name": i.name, "doc": i.doc, "default": (i.get)(&defaults).map(tidy),
                "integer": i.integer, "range": range_json(i.range), "values": i.values,
            })
        })
        .collect();
    Ok(serde_json::json!({
        "name": t.name, "doc": t.doc, "output": t.output, "display": t.display.0,
        "eval": t.eval.name(), "presets": t.presets, "settings": settings,
    }))
}

pub fn run(a: &TechniquesArgs) -> Result<()> {
    let listed: Vec<&Technique> = match a.technique {
        Some(t) => vec![t],
        None => registry().iter().collect(),
    };
    if a.json {
        let all: Vec<_> = listed.into_iter().map(technique_json).collect::<Result<_>>()?;
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({ "techniques": all }))?
        );
        return Ok(());
    }
    for t in listed {
        let defaults = t.settings(&RenderSettings::default(), None)?;
        println!("{}  —  {}", t.name, t.doc);
        println!("  output {}, eval {}", t.output, t.eval.name());
        if !t.presets.is_empty() {
            println!(
                "  presets (--preset) {} (default {})",
                t.presets.join(", "),
                t.presets[0]
            );
        }
        println!("  settings (--set NAME=VALUE): name, default, range, meaning");
        for i in t.setting_list() {
            let value = (i.get)(&defaults);
            // named values (`--set shadows=vpl`) by name, the rest as numbers
            let (d, range) = if i.values.is_empty() {
                (
                    value.map_or("scene".to_string(), |v| format!("{}", tidy(v))),
                    i.range.to_string(),
                )
            } else {
                let named = value.and_then(|v| i.values.get(v as usize)).map_or("scene", |n| n);
                (named.to_string(), i.values.join("|"))
            };
            println!("    {:<22} {:>8}  {:<12} {}", i.name, d, range, i.doc);
        }
        println!();
    }
    Ok(())
}
