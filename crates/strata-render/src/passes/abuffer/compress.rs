//! List compression (ABA §III-B, Eq. 5), the CPU twin of `compress_insert` in
//! `resolve.wgsl`: the same integer steps, so GPU and CPU keep the same nodes
//! bit for bit.
//!
//! A node is (z, α), both 16-bit: z = ⌊min(csz · depth_scale, 65535)⌋ (the
//! normalised depth z/65535 ∈ [0, 1], `depth_scale` = 65534 / the farthest
//! scene depth of the frame, so all geometry maps below 1, the empty nodes' depth) and
//! α = ⌊min(α · 65535, 65535)⌋. The array of M nodes starts as M copies of
//! (65535, 0) ("initialised with depth 1") and stays sorted by z. Inserting a
//! fragment puts it after the nodes of equal or smaller z, then removes
//! i = argmin_j α_j · (65535 − z_j) over the M + 1 nodes (ties: the largest j,
//! so the initial nodes go first) — Eq. 5 in integers, exact in 32 bits. With
//! `back_half` only j ≥ ⌊(M + 1)/2⌋ is searched: the nearest nodes always stay.

/// 1.0 in the 16-bit fixed point of depth and opacity.
pub const ONE16: u32 = 65535;

/// The packed word of an unused node: depth 1, α 0.
pub const EMPTY_NODE: u32 = ONE16 << 16;

/// The most nodes M a compressed list may keep.
pub const MAX_NODES: u32 = 16;

/// 16-bit normalised depth of camera-space depth `csz` (one f32 multiply, then truncation).
pub fn quantise_depth(csz: f32, depth_scale: f32) -> u32 {
    (csz * depth_scale).min(65535.0) as u32
}

/// 16-bit opacity (one f32 multiply, then truncation).
pub fn quantise_alpha(alpha: f32) -> u32 {
    (alpha * 65535.0).min(65535.0) as u32
}

/// A compressed list of M nodes `(z, α)`, sorted by z.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CompressedList {
    pub nodes: Vec<(u32, u32)>,
}

impl CompressedList {
    /// M nodes at depth 1 with α 0.
    pub fn new(m: u32) -> Self {
        Self {
            nodes: vec![(ONE16, 0); m as usize],
        }
    }

    /// Eq. 5: insert (z, α), then evict the node of least α·(1 − z).
    pub fn insert(&mut self, z: u32, a: u32, back_half: bool) {
        let m = self.nodes.len();
        let pos = self.nodes.iter().position(|n| n.0 > z).unwrap_or(m);
        self.nodes.insert(pos, (z, a));
        let lo = if back_half { m.div_ceil(2) } else { 0 };
        let mut evict = lo;
        let mut best = u32::MAX;
        for j in lo..=m {
            let (zj, aj) = self.nodes[j];
            let metric = aj * (ONE16 - zj);
            if metric <= best {
                best = metric;
                evict = j;
            }
        }
        self.nodes.remove(evict);
    }

    /// The nodes packed as the GPU writes them: z in the high, α in the low 16 bits.
    pub fn packed(&self) -> Vec<u32> {
        self.nodes.iter().map(|&(z, a)| (z << 16) | a).collect()
    }
}

/// Compresses a list of fragments `(csz, α)` given in resolve order (sorted by
/// depth, ties by node index) into M nodes.
pub fn compress(
    fragments: impl IntoIterator<Item = (f32, f32)>,
    m: u32,
    back_half: bool,
    depth_scale: f32,
) -> CompressedList {
    let mut c = CompressedList::new(m);
    for (csz, alpha) in fragments {
        c.insert(quantise_depth(csz, depth_scale), quantise_alpha(alpha), back_half);
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_opaque_and_near_nodes() {
        // M = 2: a far transparent node is evicted in favour of an opaque one
        let mut c = CompressedList::new(2);
        c.insert(1000, 10_000, false);
        c.insert(2000, 5_000, false);
        c.insert(3000, ONE16, false);
        assert_eq!(c.nodes, vec![(1000, 10_000), (3000, ONE16)]);
    }

    #[test]
    fn initial_nodes_go_first_and_stay_sorted() {
        let c = compress([(3.0, 0.5), (1.0, 0.25)], 4, false, 1000.0);
        assert_eq!(c.nodes, vec![(1000, 16383), (3000, 32767), (ONE16, 0), (ONE16, 0)]);
    }

    #[test]
    fn back_half_never_evicts_the_nearest() {
        // the nearest node is the least important, but with back_half it stays
        let mut all = CompressedList::new(2);
        let mut back = CompressedList::new(2);
        for (z, a) in [(100, 1), (200, 60_000), (300, 60_000)] {
            all.insert(z, a, false);
            back.insert(z, a, true);
        }
        assert_eq!(all.nodes, vec![(200, 60_000), (300, 60_000)]);
        assert_eq!(back.nodes, vec![(100, 1), (200, 60_000)]);
    }
}
