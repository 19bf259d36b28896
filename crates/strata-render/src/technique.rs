//! The technique registry: every shading technique strata renders, by name, with
//! what it outputs, how `eval` compares it and which presets it has. Tools that
//! must cover every technique (the validation matrix test, `strata techniques`)
//! iterate [`registry`]; a new technique adds one entry here and its own module.

use crate::passes::{ao::AoSettings, radiosity, reflections::ReflectionSettings};
use crate::{RenderError, RenderSettings};

/// How `eval` compares a technique's output with the CPU reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EvalKind {
    /// Not compared (no ground-truth counterpart).
    None,
    /// Ambient visibility in [0, 1] against ray-traced AO.
    AmbientVisibility,
    /// Radiance against the path tracer.
    Radiance,
}

impl EvalKind {
    pub fn name(self) -> &'static str {
        match self {
            EvalKind::None => "none",
            EvalKind::AmbientVisibility => "ambient-visibility",
            EvalKind::Radiance => "radiance",
        }
    }
}

/// One registered technique.
pub struct Technique {
    pub name: &'static str,
    /// One line: what it renders and from which paper section.
    pub doc: &'static str,
    /// The target holding the technique's image.
    pub output: &'static str,
    pub eval: EvalKind,
    /// Named parameter sets (the first is the default); empty when it has none.
    pub presets: &'static [&'static str],
    /// Turns `s` into this technique's settings with `preset` (`None`: the default
    /// preset). The caller keeps size, layers, variant and guard band; light probes
    /// (baked on the CPU) stay the caller's to add.
    pub configure: fn(&mut RenderSettings, Option<&str>) -> Result<(), RenderError>,
}

impl Technique {
    /// Settings for this technique on top of `base`.
    pub fn settings(&self, base: &RenderSettings, preset: Option<&str>) -> Result<RenderSettings, RenderError> {
        let mut s = base.clone();
        (self.configure)(&mut s, preset)?;
        Ok(s)
    }
}

fn no_preset(name: &str, preset: Option<&str>) -> Result<(), RenderError> {
    match preset {
        None => Ok(()),
        Some(p) => Err(RenderError::Parameter(format!(
            "technique '{name}' has no presets (got '{p}')"
        ))),
    }
}

fn configure_direct(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    no_preset("direct", preset)?;
    s.shade = true;
    s.ao = None;
    s.radiosity = None;
    s.reflections = None;
    Ok(())
}

fn configure_ao(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    no_preset("ao", preset)?;
    // AO alone needs no lighting passes
    s.shade = false;
    s.ao = Some(s.ao.clone().unwrap_or_default());
    s.radiosity = None;
    s.reflections = None;
    Ok(())
}

fn configure_full(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    let name = preset.unwrap_or(radiosity::PRESETS[1].0);
    let p = radiosity::Preset::named(name).map_err(RenderError::Parameter)?;
    s.shade = true;
    s.ao = Some(s.ao.clone().unwrap_or_else(AoSettings::default));
    s.radiosity = Some(p.apply(radiosity::RadiositySettings::default()));
    s.reflections = Some(s.reflections.unwrap_or_else(ReflectionSettings::default));
    Ok(())
}

/// Preset names of the DGB radiosity (Table 2), default first.
const FULL_PRESETS: &[&str] = &["balanced", "high-performance", "high-quality"];

static REGISTRY: [Technique; 3] = [
    Technique {
        name: "direct",
        doc: "direct light (shadowed sun, point, spot, rect) and emission from G-buffer layer 0, tonemapped",
        output: "ldr",
        eval: EvalKind::None,
        presets: &[],
        configure: configure_direct,
    },
    Technique {
        name: "ao",
        doc: "deep-G-buffer ambient obscurance over every layer (DGB §3.1, Eq. 1-2), temporal + bilateral filtered",
        output: "ao",
        eval: EvalKind::AmbientVisibility,
        presets: &[],
        configure: configure_ao,
    },
    Technique {
        name: "full",
        doc: "direct + deep-G-buffer radiosity (DGB §3.2-3.3) + light probes + AO + mirror reflections (§3.6)",
        output: "hdr-reflected",
        eval: EvalKind::Radiance,
        presets: FULL_PRESETS,
        configure: configure_full,
    },
];

/// Every registered technique.
pub fn registry() -> &'static [Technique] {
    &REGISTRY
}

/// The technique called `name`; the error lists the valid names.
pub fn find(name: &str) -> Result<&'static Technique, RenderError> {
    registry().iter().find(|t| t.name == name).ok_or_else(|| {
        let names: Vec<_> = registry().iter().map(|t| t.name).collect();
        RenderError::Parameter(format!(
            "unknown technique '{name}': valid techniques are {}",
            names.join(", ")
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_found() {
        for (i, t) in registry().iter().enumerate() {
            assert!(registry()[..i].iter().all(|u| u.name != t.name), "duplicate {}", t.name);
            assert_eq!(find(t.name).unwrap().name, t.name);
        }
        let e = find("nope").err().expect("unknown name").to_string();
        assert!(e.contains("direct") && e.contains("full"), "{e}");
    }

    #[test]
    fn every_preset_configures_and_validates() {
        let base = RenderSettings::default();
        for t in registry() {
            let presets: Vec<Option<&str>> = if t.presets.is_empty() {
                vec![None]
            } else {
                t.presets.iter().map(|p| Some(*p)).collect()
            };
            for p in presets {
                let s = t.settings(&base, p).unwrap();
                s.validate().unwrap();
            }
            assert!(
                t.settings(&base, Some("nope")).is_err(),
                "{} accepted an unknown preset",
                t.name
            );
        }
    }

    #[test]
    fn full_presets_are_table_2s_files() {
        let names: Vec<_> = radiosity::PRESETS.iter().map(|(n, _)| *n).collect();
        for p in FULL_PRESETS {
            assert!(names.contains(p), "{p}");
        }
        assert_eq!(FULL_PRESETS.len(), names.len());
    }
}
