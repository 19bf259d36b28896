//! An 8-wide BVH built from a binary SAH tree, with 8 boxes tested at once (AVX
//! when the CPU has it, else portable code) and 4 triangles tested at once (SSE,
//! part of x86-64; scalar elsewhere).
//!
//! - **Base tree**: the binned-SAH builder of [`Bvh`] over *pre-split*
//!   triangle references (large, badly boxed triangles get several tighter
//!   boxes; [`Bvh::build_split`]), with leaves of up to 12 triangles and the SAH
//!   counting leaf cost per packet of 4.
//! - **Collapse** (the "BVH8 from a binary tree" construction of Wald, Benthin
//!   and Boulos 2008 / Embree's BVH8): each wide node starts with a binary
//!   node's two children and repeatedly replaces the interior child with the
//!   largest surface area by its two children until it has 8 children or only
//!   leaves. A leaf is stored as up to 3 structure-of-arrays packets of 4
//!   triangles.
//! - **Box test**: the binary tree's slab test (Ize 2013 far-distance scale,
//!   finite reciprocals) on 8 children per node, over the `[tmin, tmax]` range
//!   widened by [`crate::bvh::BOX_SLACK`].
//! - **Triangle test**: the same watertight test (Woop, Benthin, Wald 2013) over
//!   the 4 triangles of a leaf in SSE lanes, operation for operation as the
//!   scalar code (no fused multiply-add), so `t` and the barycentrics are
//!   bitwise those of [`Bvh`]; a lane with a zero edge function is redone by the
//!   scalar test, which has the `f64` fallback.
//! - **Traversal**: closest hit visits children nearest first (sorted entry
//!   distances) and keeps equal-`t` candidates for the lowest-index tie-break;
//!   occlusion rays stop at the first hit and do not sort.
//!
//! Because the hit *set* does not depend on the tree (box tests are conservative
//! with a margin, see [`crate::bvh::BOX_SLACK`]; a pre-split triangle's hits are
//! bitwise equal and `intersect_all` drops the duplicates) and the closest hit is
//! the lexicographic minimum of (t, triangle) over that set, every query returns
//! exactly what [`Bvh`] returns (tested ray by ray in `tests/reference/tracer.rs`).

use std::mem::MaybeUninit;

use glam::Vec3;
use strata_scene::WorldTriangle;

use crate::bvh::{
    box_range, next_up, scale_of, start_traversal, Bvh, ChildRef, Hit, LeafPolicy, Ray, TraversalStart, BOX_SCALE, LEAF,
};

/// Children per node.
pub(crate) const WIDTH: usize = 8;
/// Traversal stack entries: a wide node pushes at most 7 children and the wide
/// tree is no deeper than the binary tree (checked at build, see `max_depth`).
pub(crate) const STACK: usize = 1024;

/// A wide node: the boxes of its 8 children as `[axis][child]` (structure of
/// arrays) and their references. Empty slots have an inverted box (lo = +∞,
/// hi = −∞) that no ray enters.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Node8 {
    pub(crate) lo: [[f32; WIDTH]; 3],
    pub(crate) hi: [[f32; WIDTH]; 3],
    pub(crate) child: [ChildRef; WIDTH],
}

/// The ≤ 4 triangles of one leaf: `p[vertex][axis][lane]`.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(crate) struct Packet {
    p: [[[f32; 4]; 3]; 3],
}

impl Packet {
    #[inline(always)]
    fn vertices(&self, lane: usize) -> [Vec3; 3] {
        let v = |k: usize| Vec3::new(self.p[k][0][lane], self.p[k][1][lane], self.p[k][2][lane]);
        [v(0), v(1), v(2)]
    }
}

/// The 8-wide BVH. Built from (and answering exactly like) the binary [`Bvh`].
pub struct WideBvh {
    pub(crate) nodes: Vec<Node8>,
    /// Root reference (a node, or a leaf when the scene has ≤ 4 triangles) and bounds.
    pub(crate) root: Option<(ChildRef, [f32; 3], [f32; 3])>,
    pub(crate) packets: Vec<Packet>,
    /// Triangle index of each packet lane.
    ids: Vec<[u32; 4]>,
    triangles: Vec<WorldTriangle>,
    /// Use the AVX box test (runtime-detected).
    pub(crate) avx: bool,
}

impl Node8 {
    const EMPTY: Node8 = Node8 {
        lo: [[f32::INFINITY; WIDTH]; 3],
        hi: [[f32::NEG_INFINITY; WIDTH]; 3],
        child: [0; WIDTH],
    };
}

/// New references per triangle allowed by pre-splitting ([`Bvh::build_split`]):
/// on Sponza 0.25 cuts the wide nodes an AO ray visits by a fifth (7.2 → 5.7);
/// more splitting visits more leaves again.
const PRESPLIT_EXTRA: f32 = 0.25;

/// The binary tree the wide one is collapsed from: binned SAH over
/// pre-split triangle references.
pub(crate) fn base_tree(triangles: Vec<WorldTriangle>) -> Bvh {
    Bvh::build_split(triangles, PRESPLIT_EXTRA, LEAF_POLICY)
}

/// Leaves of up to 12 triangles (three SSE packets), SAH cost per packet of 4
/// (on the Sponza AO job 12 beat 8 and 15 by 5–13 %, within this shared
/// machine's noise; instruction counts were within 2 %).
const LEAF_POLICY: LeafPolicy = LeafPolicy { max: 12, block: 4 };
/// Most packets in one leaf.
const MAX_PACKETS: usize = 3;

/// What a traversal does with hits.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Nearest first; the callback shrinks `tmax`.
    Closest,
    /// Every hit (occlusion rays have their own traversal, [`WideBvh::occluded`]).
    All,
}

impl WideBvh {
    /// Builds the binary SAH tree (with pre-split references, see
    /// [`base_tree`]) and collapses it.
    pub fn build(triangles: Vec<WorldTriangle>) -> Self {
        Self::from_binary(base_tree(triangles))
    }

    /// Collapses a binary tree into a wide one (the binary nodes are dropped).
    pub fn from_binary(bvh: Bvh) -> Self {
        let mut w = WideBvh {
            nodes: Vec::with_capacity(bvh.nodes.len() / 4 + 1),
            root: None,
            packets: Vec::with_capacity(bvh.verts.len() / 2 + 1),
            ids: Vec::with_capacity(bvh.verts.len() / 2 + 1),
            triangles: Vec::new(),
            avx: detect_avx(),
        };
        if let Some((root, lo, hi)) = bvh.root {
            let r = if root & LEAF != 0 {
                w.leaf(&bvh, root)
            } else {
                let mut depth = 0;
                let r = w.collapse(&bvh, root, 1, &mut depth);
                // The stack bound: at most 7 pushes per level.
                debug_assert!(depth * (WIDTH - 1) < STACK);
                r
            };
            w.root = Some((r, lo, hi));
        }
        w.triangles = bvh.triangles;
        w
    }

    /// Uses (`true`, when the CPU has AVX) or avoids the AVX box test: the
    /// portable path must answer identically (tested).
    pub fn with_simd(mut self, on: bool) -> Self {
        self.avx = on && detect_avx();
        self
    }

    /// True when the AVX box test is in use.
    pub fn simd(&self) -> bool {
        self.avx
    }

    /// The triangles, in the order given to [`WideBvh::build`].
    pub fn triangles(&self) -> &[WorldTriangle] {
        &self.triangles
    }

    /// Number of wide nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// World bounds of everything in the hierarchy, or `None` when empty.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.root.map(|(_, lo, hi)| (Vec3::from(lo), Vec3::from(hi)))
    }

    /// Packets for the binary leaf `leaf` (4 triangles each); returns the wide
    /// leaf reference `LEAF | first packet << 4 | triangle count`.
    fn leaf(&mut self, bvh: &Bvh, leaf: ChildRef) -> ChildRef {
        let first = ((leaf & !LEAF) >> 4) as usize;
        let count = ((leaf & 15) as usize).min(4 * MAX_PACKETS);
        let index = self.packets.len();
        for chunk in (first..first + count).collect::<Vec<_>>().chunks(4) {
            let mut pk = Packet { p: [[[0.0; 4]; 3]; 3] };
            let mut ids = [u32::MAX; 4];
            for (lane, &i) in chunk.iter().enumerate() {
                for (k, v) in bvh.verts[i].iter().enumerate() {
                    for axis in 0..3 {
                        pk.p[k][axis][lane] = v[axis];
                    }
                }
                ids[lane] = bvh.ids[i];
            }
            self.packets.push(pk);
            self.ids.push(ids);
        }
        LEAF | (index as u32) << 4 | count as u32
    }

    /// Collapses the binary subtree under interior node `node` (depth-first,
    /// parent before children); returns the wide node's index.
    fn collapse(&mut self, bvh: &Bvh, node: ChildRef, depth: usize, max_depth: &mut usize) -> ChildRef {
        *max_depth = (*max_depth).max(depth);
        let area = |lo: &[f32; 3], hi: &[f32; 3]| {
            let d = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
            d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
        };
        let n = &bvh.nodes[node as usize];
        let mut kids: Vec<(ChildRef, [f32; 3], [f32; 3])> =
            vec![(n.child[0], n.min[0], n.max[0]), (n.child[1], n.min[1], n.max[1])];
        while kids.len() < WIDTH {
            // Open the interior child with the largest surface area.
            let Some((i, _)) = kids
                .iter()
                .enumerate()
                .filter(|(_, k)| k.0 & LEAF == 0)
                .map(|(i, k)| (i, area(&k.1, &k.2)))
                .max_by(|a, b| a.1.total_cmp(&b.1))
            else {
                break;
            };
            let c = &bvh.nodes[kids[i].0 as usize];
            kids[i] = (c.child[0], c.min[0], c.max[0]);
            kids.insert(i + 1, (c.child[1], c.min[1], c.max[1]));
        }
        let index = self.nodes.len();
        self.nodes.push(Node8::EMPTY);
        for (slot, (c, lo, hi)) in kids.into_iter().enumerate() {
            let r = if c & LEAF != 0 {
                self.leaf(bvh, c)
            } else {
                self.collapse(bvh, c, depth + 1, max_depth)
            };
            let nd = &mut self.nodes[index];
            for axis in 0..3 {
                nd.lo[axis][slot] = lo[axis];
                nd.hi[axis][slot] = hi[axis];
            }
            nd.child[slot] = r;
        }
        index as ChildRef
    }

    /// Starts loading child `c` (a node's 256 bytes, or a leaf's packets)
    /// into the cache: incoherent rays in large scenes wait mostly on these
    /// loads (perf on the dragon's diffuse rays), and a pushed child is
    /// visited only after its siblings.
    #[inline(always)]
    pub(crate) fn prefetch(&self, c: ChildRef) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let (base, bytes) = if c & LEAF != 0 {
                let first = ((c & !LEAF) >> 4) as usize;
                let packets = ((c & 15) as usize).div_ceil(4);
                (
                    &self.packets[first] as *const Packet as *const i8,
                    packets * size_of::<Packet>(),
                )
            } else {
                (&self.nodes[c as usize] as *const Node8 as *const i8, size_of::<Node8>())
            };
            for offset in (0..bytes).step_by(64) {
                // SAFETY: `offset` stays inside the leaf's packets / the node
                // (contiguous in their vectors); prefetching never faults.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(base.add(offset)) };
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = c;
    }

    /// Closest hit with `tmin < t < tmax`; ties at equal `t` go to the lowest triangle index.
    pub fn intersect(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut tmax = tmax;
        self.dispatch(
            origin,
            dir,
            tmin,
            &mut tmax,
            Mode::Closest,
            &mut |hit: Hit, tmax: &mut f32| {
                let better = match best {
                    None => true,
                    Some(b) => hit.t < b.t || (hit.t == b.t && hit.triangle < b.triangle),
                };
                if better {
                    best = Some(hit);
                    // Keep equal-t candidates reachable for the tie-break.
                    *tmax = next_up(hit.t);
                }
                false
            },
        );
        best
    }

    /// Any hit with `tmin < t < tmax` (shadow / visibility rays).
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> bool {
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is only true when the CPU reports AVX.
            return unsafe { self.any_hit_avx(origin, dir, tmin, tmax) };
        }
        self.any_hit::<false>(origin, dir, tmin, tmax)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn any_hit_avx(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> bool {
        self.any_hit::<true>(origin, dir, tmin, tmax)
    }

    /// Occlusion traversal: no ordering, no distances kept, stop at the first
    /// hit (`tmax` never shrinks, so a pushed child is never culled later).
    #[inline(always)]
    fn any_hit<const AVX: bool>(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> bool {
        let Some((root, root_min, root_max)) = self.root else {
            return false;
        };
        if !(tmin <= tmax) || !origin.is_finite() || !dir.is_finite() {
            return false;
        }
        let ray = Ray::new(origin, dir);
        let (btmin, btmax) = box_range(tmin, tmax, ray.margin(dir, scale_of(&root_min, &root_max)));
        // A root node tests its children's boxes at once; only a root leaf
        // needs the bounds test.
        if root & LEAF != 0 && ray.hit_box(&root_min, &root_max, btmin, btmax) == f32::INFINITY {
            return false;
        }
        let mut stack = [const { MaybeUninit::<ChildRef>::uninit() }; STACK];
        let mut sp = 0usize;
        let mut cur = root;
        loop {
            if cur & LEAF != 0 {
                let first = ((cur & !LEAF) >> 4) as usize;
                let total = (cur & 15) as usize;
                for index in first..first + total.div_ceil(4) {
                    let count = (total - 4 * (index - first)).min(4);
                    if hit_packet(&self.packets[index], count, &ray, tmin, tmax).0 != 0 {
                        return true;
                    }
                }
            } else {
                let node = &self.nodes[cur as usize];
                let mut near = [0.0f32; WIDTH];
                let mut mask = box8::<AVX>(node, &ray, btmin, btmax, &mut near);
                if mask != 0 {
                    cur = node.child[mask.trailing_zeros() as usize];
                    mask &= mask - 1;
                    while mask != 0 {
                        let c = node.child[mask.trailing_zeros() as usize];
                        self.prefetch(c);
                        stack[sp].write(c);
                        sp += 1;
                        mask &= mask - 1;
                    }
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: entries below `sp` were written by the pushes above.
            cur = unsafe { stack[sp].assume_init() };
        }
    }

    /// All hits with `tmin < t < tmax`, sorted by (t, triangle), into `out` (cleared first).
    pub fn intersect_all(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32, out: &mut Vec<Hit>) {
        out.clear();
        let mut tmax = tmax;
        self.dispatch(origin, dir, tmin, &mut tmax, Mode::All, &mut |hit, _| {
            out.push(hit);
            false
        });
        out.sort_unstable_by(|a, b| a.t.total_cmp(&b.t).then(a.triangle.cmp(&b.triangle)));
        // A pre-split triangle sits in several leaves; its hits are bitwise equal.
        out.dedup_by(|a, b| a.triangle == b.triangle && a.t == b.t);
    }

    /// The nearest hit strictly beyond `t_after` (and below `tmax`).
    pub fn next_hit(&self, origin: Vec3, dir: Vec3, t_after: f32, tmax: f32) -> Option<Hit> {
        self.intersect(origin, dir, t_after, tmax)
    }

    /// Surface attributes of `hit` for a ray travelling along `dir`.
    pub fn surface(&self, hit: &Hit, dir: Vec3) -> crate::SurfaceHit {
        crate::bvh::surface_of(&self.triangles[hit.triangle as usize], hit, dir)
    }

    #[inline(always)]
    fn dispatch<F: FnMut(Hit, &mut f32) -> bool>(
        &self,
        origin: Vec3,
        dir: Vec3,
        tmin: f32,
        tmax: &mut f32,
        mode: Mode,
        on_hit: &mut F,
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is only true when the CPU reports AVX.
            unsafe { self.traverse_avx(origin, dir, tmin, tmax, mode, on_hit) };
            return;
        }
        self.traverse::<false, F>(origin, dir, tmin, tmax, mode, on_hit);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn traverse_avx<F: FnMut(Hit, &mut f32) -> bool>(
        &self,
        origin: Vec3,
        dir: Vec3,
        tmin: f32,
        tmax: &mut f32,
        mode: Mode,
        on_hit: &mut F,
    ) {
        self.traverse::<true, F>(origin, dir, tmin, tmax, mode, on_hit);
    }

    /// Shared traversal: calls `on_hit(hit, &mut tmax)` for every triangle hit in
    /// range (the callback may shrink `tmax`); stops when it returns true.
    #[inline(always)]
    fn traverse<const AVX: bool, F: FnMut(Hit, &mut f32) -> bool>(
        &self,
        origin: Vec3,
        dir: Vec3,
        tmin: f32,
        tmax: &mut f32,
        mode: Mode,
        on_hit: &mut F,
    ) {
        let Some(TraversalStart {
            root,
            ray,
            margin,
            btmin,
            mut btmax,
            root_near,
        }) = start_traversal(self.root, origin, dir, tmin, *tmax)
        else {
            return;
        };
        // Uninitialised: zeroing 8 KiB per ray would cost more than the traversal.
        let mut stack = [const { MaybeUninit::<(ChildRef, f32)>::uninit() }; STACK];
        let mut sp = 0usize;
        let mut cur = root;
        let mut cur_near = root_near;
        loop {
            if cur_near <= btmax {
                if cur & LEAF != 0 {
                    let first = ((cur & !LEAF) >> 4) as usize;
                    let total = (cur & 15) as usize;
                    for index in first..first + total.div_ceil(4) {
                        let count = (total - 4 * (index - first)).min(4);
                        let (mask, t, b1, b2) = hit_packet(&self.packets[index], count, &ray, tmin, *tmax);
                        if mask != 0 {
                            let ids = &self.ids[index];
                            for lane in 0..4 {
                                if mask & (1 << lane) == 0 {
                                    continue;
                                }
                                // A hit accepted under the tmax in force when the packet
                                // was tested; a lane before it may have shrunk tmax.
                                if !(t[lane] < *tmax) {
                                    continue;
                                }
                                let hit = Hit {
                                    t: t[lane],
                                    triangle: ids[lane],
                                    b1: b1[lane],
                                    b2: b2[lane],
                                };
                                if on_hit(hit, tmax) {
                                    return;
                                }
                            }
                            btmax = box_range(tmin, *tmax, margin).1;
                        }
                    }
                } else {
                    let node = &self.nodes[cur as usize];
                    let mut near = [0.0f32; WIDTH];
                    let mut mask = box8::<AVX>(node, &ray, btmin, btmax, &mut near);
                    if mask != 0 {
                        if mode == Mode::Closest && mask & (mask - 1) != 0 {
                            // Nearest first: sort the hit children by entry distance,
                            // push all but the nearest, farthest first.
                            let mut items = [(0 as ChildRef, 0.0f32); WIDTH];
                            let mut k = 0;
                            while mask != 0 {
                                let i = mask.trailing_zeros() as usize;
                                mask &= mask - 1;
                                let item = (node.child[i], near[i]);
                                self.prefetch(item.0);
                                let mut j = k;
                                while j > 0 && items[j - 1].1 > item.1 {
                                    items[j] = items[j - 1];
                                    j -= 1;
                                }
                                items[j] = item;
                                k += 1;
                            }
                            for item in items[1..k].iter().rev() {
                                stack[sp].write(*item);
                                sp += 1;
                            }
                            (cur, cur_near) = items[0];
                        } else {
                            let i = mask.trailing_zeros() as usize;
                            mask &= mask - 1;
                            (cur, cur_near) = (node.child[i], near[i]);
                            while mask != 0 {
                                let i = mask.trailing_zeros() as usize;
                                mask &= mask - 1;
                                self.prefetch(node.child[i]);
                                stack[sp].write((node.child[i], near[i]));
                                sp += 1;
                            }
                        }
                        continue;
                    }
                }
            }
            if sp == 0 {
                return;
            }
            sp -= 1;
            // SAFETY: entries below `sp` were written by the pushes above.
            (cur, cur_near) = unsafe { stack[sp].assume_init() };
        }
    }
}

#[cfg(target_arch = "x86_64")]
fn detect_avx() -> bool {
    std::arch::is_x86_feature_detected!("avx")
}

#[cfg(not(target_arch = "x86_64"))]
fn detect_avx() -> bool {
    false
}

/// The slab test of [`Ray::hit_box`] on a node's 8 children: bit i of the result
/// is set when child i overlaps `[tmin, tmax]`, with its entry distance in `near[i]`.
#[inline(always)]
fn box8<const AVX: bool>(node: &Node8, ray: &Ray, tmin: f32, tmax: f32, near: &mut [f32; WIDTH]) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: `AVX` is only instantiated inside `traverse_avx`, which runs
        // only when the CPU has AVX.
        return unsafe { box8_avx(node, ray, tmin, tmax, near) };
    }
    box8_portable(node, ray, tmin, tmax, near)
}

#[inline(always)]
fn box8_portable(node: &Node8, ray: &Ray, tmin: f32, tmax: f32, near_out: &mut [f32; WIDTH]) -> u32 {
    let mut near = [tmin; WIDTH];
    let mut far = [tmax; WIDTH];
    for k in 0..3 {
        let (lo, hi) = if ray.neg[k] {
            (&node.hi[k], &node.lo[k])
        } else {
            (&node.lo[k], &node.hi[k])
        };
        let (o, inv) = (ray.org[k], ray.inv[k]);
        for i in 0..WIDTH {
            let t0 = (lo[i] - o) * inv;
            let t1 = (hi[i] - o) * inv * BOX_SCALE;
            near[i] = if t0 > near[i] { t0 } else { near[i] };
            far[i] = if t1 < far[i] { t1 } else { far[i] };
        }
    }
    let mut mask = 0;
    for i in 0..WIDTH {
        mask |= ((near[i] <= far[i]) as u32) << i;
    }
    *near_out = near;
    mask
}

/// [`box8_portable`] in AVX registers (same operations, same order, so the
/// same mask and distances).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
unsafe fn box8_avx(node: &Node8, ray: &Ray, tmin: f32, tmax: f32, near_out: &mut [f32; WIDTH]) -> u32 {
    use std::arch::x86_64::*;
    let mut near = _mm256_set1_ps(tmin);
    let mut far = _mm256_set1_ps(tmax);
    let scale = _mm256_set1_ps(BOX_SCALE);
    for k in 0..3 {
        let (lo, hi) = if ray.neg[k] {
            (&node.hi[k], &node.lo[k])
        } else {
            (&node.lo[k], &node.hi[k])
        };
        let o = _mm256_set1_ps(ray.org[k]);
        let inv = _mm256_set1_ps(ray.inv[k]);
        // SAFETY: 32 readable bytes each (`[f32; 8]`); unaligned loads.
        let (lo, hi) = unsafe { (_mm256_loadu_ps(lo.as_ptr()), _mm256_loadu_ps(hi.as_ptr())) };
        let t0 = _mm256_mul_ps(_mm256_sub_ps(lo, o), inv);
        let t1 = _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(hi, o), inv), scale);
        // max_ps(a, b) = a > b ? a : b, min_ps(a, b) = a < b ? a : b: the scalar selects.
        near = _mm256_max_ps(t0, near);
        far = _mm256_min_ps(t1, far);
    }
    // SAFETY: 32 writable bytes.
    unsafe { _mm256_storeu_ps(near_out.as_mut_ptr(), near) };
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32
}

/// The watertight test of [`Ray::hit_triangle`] on the `count` triangles of a
/// packet: bit i of the mask is set when lane i hits at `tmin < t < tmax`.
#[inline(always)]
pub(crate) fn hit_packet(
    pk: &Packet,
    count: usize,
    ray: &Ray,
    tmin: f32,
    tmax: f32,
) -> (u32, [f32; 4], [f32; 4], [f32; 4]) {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { hit_packet_sse(pk, count, ray, tmin, tmax) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        hit_packet_scalar(pk, count, ray, tmin, tmax)
    }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn hit_packet_scalar(
    pk: &Packet,
    count: usize,
    ray: &Ray,
    tmin: f32,
    tmax: f32,
) -> (u32, [f32; 4], [f32; 4], [f32; 4]) {
    let (mut mask, mut t, mut b1, mut b2) = (0u32, [0.0; 4], [0.0; 4], [0.0; 4]);
    for lane in 0..count.min(4) {
        if let Some((tt, u, v)) = ray.hit_triangle(&pk.vertices(lane), tmin, tmax) {
            mask |= 1 << lane;
            (t[lane], b1[lane], b2[lane]) = (tt, u, v);
        }
    }
    (mask, t, b1, b2)
}

/// SSE version of the watertight test, lane for lane the scalar operations
/// (Woop et al. 2013): shear to the ray's frame, 2D edge functions, signs, det,
/// scaled t. Lanes with a zero edge function go to the scalar test (its `f64`
/// recomputation decides them).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn hit_packet_sse(
    pk: &Packet,
    count: usize,
    ray: &Ray,
    tmin: f32,
    tmax: f32,
) -> (u32, [f32; 4], [f32; 4], [f32; 4]) {
    use std::arch::x86_64::*;
    let valid = (1u32 << count.min(4)) - 1;
    let (kx, ky, kz) = (ray.kx, ray.ky, ray.kz);
    let (sx, sy, sz) = (_mm_set1_ps(ray.sx), _mm_set1_ps(ray.sy), _mm_set1_ps(ray.sz));
    let org = [ray.org.x, ray.org.y, ray.org.z];
    // SAFETY (loads): each `[f32; 4]` is 16 readable bytes; unaligned loads.
    let rel = |v: usize, k: usize| unsafe { _mm_sub_ps(_mm_loadu_ps(pk.p[v][k].as_ptr()), _mm_set1_ps(org[k])) };
    let (az, bz, cz) = (rel(0, kz), rel(1, kz), rel(2, kz));
    let ax = _mm_sub_ps(rel(0, kx), _mm_mul_ps(sx, az));
    let ay = _mm_sub_ps(rel(0, ky), _mm_mul_ps(sy, az));
    let bx = _mm_sub_ps(rel(1, kx), _mm_mul_ps(sx, bz));
    let by = _mm_sub_ps(rel(1, ky), _mm_mul_ps(sy, bz));
    let cx = _mm_sub_ps(rel(2, kx), _mm_mul_ps(sx, cz));
    let cy = _mm_sub_ps(rel(2, ky), _mm_mul_ps(sy, cz));
    let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
    let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
    let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
    let zero = _mm_setzero_ps();
    let any_zero = _mm_or_ps(
        _mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)),
        _mm_cmpeq_ps(w, zero),
    );
    let any_neg = _mm_or_ps(
        _mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)),
        _mm_cmplt_ps(w, zero),
    );
    let any_pos = _mm_or_ps(
        _mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)),
        _mm_cmpgt_ps(w, zero),
    );
    let det = _mm_add_ps(_mm_add_ps(u, v), w);
    let t_scaled = _mm_add_ps(
        _mm_add_ps(_mm_mul_ps(u, _mm_mul_ps(sz, az)), _mm_mul_ps(v, _mm_mul_ps(sz, bz))),
        _mm_mul_ps(w, _mm_mul_ps(sz, cz)),
    );
    let rcp = _mm_div_ps(_mm_set1_ps(1.0), det);
    let t = _mm_mul_ps(t_scaled, rcp);
    let ok = _mm_andnot_ps(
        _mm_or_ps(_mm_and_ps(any_neg, any_pos), _mm_cmpeq_ps(det, zero)),
        _mm_and_ps(_mm_cmpgt_ps(t, _mm_set1_ps(tmin)), _mm_cmplt_ps(t, _mm_set1_ps(tmax))),
    );
    let zero_mask = _mm_movemask_ps(any_zero) as u32 & valid;
    let mut mask = _mm_movemask_ps(ok) as u32 & valid & !zero_mask;
    let (mut to, mut b1o, mut b2o) = ([0.0f32; 4], [0.0f32; 4], [0.0f32; 4]);
    if mask != 0 {
        // SAFETY: 16 writable bytes each.
        unsafe {
            _mm_storeu_ps(to.as_mut_ptr(), t);
            _mm_storeu_ps(b1o.as_mut_ptr(), _mm_mul_ps(v, rcp));
            _mm_storeu_ps(b2o.as_mut_ptr(), _mm_mul_ps(w, rcp));
        }
    }
    let mut zm = zero_mask;
    while zm != 0 {
        let lane = zm.trailing_zeros() as usize;
        zm &= zm - 1;
        if let Some((tt, u, v)) = ray.hit_triangle(&pk.vertices(lane), tmin, tmax) {
            mask |= 1 << lane;
            (to[lane], b1o[lane], b2o[lane]) = (tt, u, v);
        }
    }
    (mask, to, b1o, b2o)
}
