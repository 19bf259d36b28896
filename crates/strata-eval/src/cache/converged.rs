//! Converged references in the cache: the two half images of
//! [`strata_reference::Converged`] (`<key>-a`, `<key>-b`) and what the convergence measured
//! (`<key>.json`), so a reference converged once is never integrated again.

use serde::{Deserialize, Serialize};
use strata_reference::converge::Round;
use strata_reference::{Converged, Estimator};

use super::RefCache;

/// What is stored beside the halves.
#[derive(Serialize, Deserialize)]
struct Meta {
    spp_per_half: u32,
    noise: f64,
    converged: bool,
    /// (total spp, noise, seconds) per round.
    rounds: Vec<(u32, f64, f64)>,
}

impl RefCache {
    /// The converged reference for `description` (which must name the estimator, its settings
    /// and the convergence rule), from the cache unless `refresh`, else computed by `compute` and
    /// stored (a failure to store is logged).
    pub fn converged(
        &self,
        refresh: bool,
        description: &str,
        estimator: &Estimator,
        compute: impl FnOnce() -> Converged,
    ) -> Converged {
        let key = RefCache::key(description);
        let half_keys = [format!("{key}-a"), format!("{key}-b")];
        if !refresh {
            let meta = self.load_json::<Meta>(&key);
            let halves = half_keys.each_ref().map(|k| self.load(k));
            if let (Some(m), [Some(a), Some(b)]) = (meta, halves) {
                if a.channels == estimator.channels() && (a.width, a.height) == (b.width, b.height) {
                    tracing::info!("converged reference {key} from {}", self.dir().display());
                    return Converged {
                        estimator: *estimator,
                        halves: [a, b],
                        spp_per_half: m.spp_per_half,
                        noise: m.noise,
                        converged: m.converged,
                        rounds: m
                            .rounds
                            .iter()
                            .map(|&(spp, noise, seconds)| Round { spp, noise, seconds })
                            .collect(),
                    };
                }
            }
        }
        let c = compute();
        for (k, (img, half)) in half_keys.iter().zip(c.halves.iter().zip(["a", "b"])) {
            self.store_or_warn(k, img, &format!("{description} half {half}"));
        }
        let meta = Meta {
            spp_per_half: c.spp_per_half,
            noise: c.noise,
            converged: c.converged,
            rounds: c.rounds.iter().map(|r| (r.spp, r.noise, r.seconds)).collect(),
        };
        if let Err(e) = self.store_json(&key, &meta) {
            tracing::warn!("could not cache the reference: {e:#}");
        }
        c
    }
}
