//! A binned-SAH bounding volume hierarchy over world-space triangles with
//! watertight ray–triangle intersection.
//!
//! - **Build**: top-down, 16 SAH bins per axis over triangle centroids, leaves of
//!   at most [`MAX_LEAF`] triangles (up to 2²⁸ triangles in all); interior nodes
//!   are flattened depth-first into 64-byte records that hold *both* children's
//!   boxes and references (a leaf is a packed reference in its parent), so each
//!   visit touches one cache line.
//! - **Intersection**: the watertight algorithm of Woop, Benthin and Wald
//!   (JCGT 2013): the ray is sheared so it runs along +Z, the edge functions are
//!   evaluated in 2D and recomputed in `f64` when one is exactly zero. A ray
//!   through a shared edge or vertex of a closed mesh never slips between
//!   triangles, and the result does not depend on traversal order.
//! - **Traversal**: the box test scales the far distance by `1 + 2γ₃` (Ize 2013)
//!   so boxes are never culled by rounding; slabs are picked by the direction's
//!   signs; zero direction components give infinite reciprocals and the NaN of
//!   `0 · ∞` (a ray lying in a slab plane) counts as inside, so a ray along a
//!   box face still enters it; the `[tmin, tmax]` range of the box tests is
//!   widened by a small margin ([`BOX_SLACK`]) so culling never depends on
//!   traversal order; closest-hit visits the nearer child first.
//!
//! `t` is measured in units of the ray direction as given (directions need not be
//! normalised: primary rays use [`strata_scene::Camera::pixel_dir`], so `t` is the
//! camera-space depth).

use std::mem::MaybeUninit;

use glam::{Vec3, Vec4};
use strata_scene::WorldTriangle;

/// Most triangles in one leaf.
pub const MAX_LEAF: usize = 4;
/// SAH bins per axis.
pub const BINS: usize = 16;
/// Depth beyond which the build switches to balanced median splits, bounding the
/// traversal stack.
const MAX_SAH_DEPTH: usize = 96;
const STACK: usize = 128;
/// `1 + 2γ₃` with γₙ = nε/(1 − nε), ε = 2⁻²⁴: conservative slab-test scale.
pub(crate) const BOX_SCALE: f32 = 1.000_000_4;
/// Slack of the `[tmin, tmax]` range the *box* tests use (the triangle test
/// uses the exact range): relative to the range ends, plus an absolute margin
/// of `BOX_SLACK ×` the coordinate magnitude along the ray (see
/// [`Ray::margin`]). A box whose computed entry distance lies a few ulps
/// beyond a triangle hit's computed `t` (a triangle lying in the box's entry
/// face; a ray starting on the triangle it hits) is still visited, so culling
/// never depends on the order boxes are visited in, and every backend finds the
/// same hits. 2⁻¹⁸ ≈ 4e-6.
pub(crate) const BOX_SLACK: f32 = 1.0 / 262_144.0;

/// The start of a traversal: the root, the ray, the absolute box margin, the widened
/// box range ([`box_range`]) and the root box's entry distance.
pub(crate) struct TraversalStart {
    pub root: ChildRef,
    pub ray: Ray,
    pub margin: f32,
    pub btmin: f32,
    pub btmax: f32,
    pub root_near: f32,
}

/// [`TraversalStart`] of a tree with `root` (a node or leaf and its world bounds); `None`
/// when the tree is empty, `[tmin, tmax]` is empty or not a number, the ray is not
/// finite, or it misses the root box.
#[inline(always)]
pub(crate) fn start_traversal(
    root: Option<(ChildRef, [f32; 3], [f32; 3])>,
    origin: Vec3,
    dir: Vec3,
    tmin: f32,
    tmax: f32,
) -> Option<TraversalStart> {
    let (root, root_min, root_max) = root?;
    if !(tmin <= tmax) || !origin.is_finite() || !dir.is_finite() {
        return None;
    }
    let ray = Ray::new(origin, dir);
    let margin = ray.margin(dir, scale_of(&root_min, &root_max));
    let (btmin, btmax) = box_range(tmin, tmax, margin);
    let root_near = ray.hit_box(&root_min, &root_max, btmin, btmax);
    (root_near != f32::INFINITY).then_some(TraversalStart {
        root,
        ray,
        margin,
        btmin,
        btmax,
        root_near,
    })
}

/// The `[tmin, tmax]` range widened by [`BOX_SLACK`] and the absolute `margin`
/// for box tests.
#[inline(always)]
pub(crate) fn box_range(tmin: f32, tmax: f32, margin: f32) -> (f32, f32) {
    (
        tmin - tmin.abs() * BOX_SLACK - margin,
        tmax + tmax.abs() * BOX_SLACK + margin,
    )
}

/// A ray–triangle hit: parametric distance, triangle index into the triangle
/// list the BVH was built from, and barycentric weights of vertices 1 and 2
/// (vertex 0 has weight `1 − b1 − b2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub triangle: u32,
    pub b1: f32,
    pub b2: f32,
}

/// Surface attributes at a hit, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    pub t: f32,
    pub triangle: u32,
    /// Interpolated from the triangle's vertices with the hit's barycentrics.
    pub position: Vec3,
    /// Unit normal of the triangle plane, oriented by the counter-clockwise
    /// winding (`(p1 − p0) × (p2 − p0)`), not flipped towards the ray.
    pub geometric_normal: Vec3,
    /// Interpolated, normalised vertex normal, not flipped towards the ray; the
    /// geometric normal when the vertex normals are degenerate.
    pub shading_normal: Vec3,
    /// True when the ray arrives at the counter-clockwise (front) side.
    pub front_face: bool,
    pub uv: [f32; 2],
    pub material: u32,
    pub object: u32,
}

impl SurfaceHit {
    /// (shading, geometric) normals on the side the ray `dir` came from: both
    /// are flipped when the ray arrives at the back of the *geometric* surface
    /// (`geometric · dir > 0`), as the GPU flips back faces' normals by
    /// `front_facing`. The geometric normal then faces the ray; the shading
    /// normal stays on the geometric normal's side of the surface even where it
    /// points slightly away from the viewer (silhouettes of smooth meshes).
    /// Flipping the shading normal by its own dot product with `dir` instead
    /// would turn it into the surface there, and every hemisphere ray would hit
    /// the surface itself: the isolated black pixels `docs/reference.md`
    /// traces back to this.
    pub fn facing_normals(&self, dir: Vec3) -> (Vec3, Vec3) {
        if self.geometric_normal.dot(dir) > 0.0 {
            (-self.shading_normal, -self.geometric_normal)
        } else {
            (self.shading_normal, self.geometric_normal)
        }
    }
}

/// A reference to a child: an interior node index, or (high bit set) a leaf
/// holding `count ≤ 15` triangles (≤ [`MAX_LEAF`] in [`Bvh::build`]'s trees)
/// starting at `first` in leaf order, packed as `LEAF | first << 4 | count`.
pub(crate) type ChildRef = u32;
pub(crate) const LEAF: u32 = 1 << 31;

#[inline(always)]
fn leaf_ref(first: usize, count: usize) -> ChildRef {
    debug_assert!(count <= 15 && first < (1 << 27));
    LEAF | (first as u32) << 4 | count as u32
}

/// Interior node holding both children's boxes (one 64-byte cache line per
/// visit), flattened depth-first.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Node {
    /// `[left, right]` child boxes.
    pub(crate) min: [[f32; 3]; 2],
    pub(crate) max: [[f32; 3]; 2],
    pub(crate) child: [ChildRef; 2],
}

/// Precomputed per-ray data for the slab and watertight tests.
#[derive(Clone, Copy)]
pub(crate) struct Ray {
    pub(crate) org: Vec3,
    pub(crate) inv: [f32; 3],
    pub(crate) neg: [bool; 3],
    pub(crate) kx: usize,
    pub(crate) ky: usize,
    pub(crate) kz: usize,
    pub(crate) sx: f32,
    pub(crate) sy: f32,
    pub(crate) sz: f32,
}

impl Ray {
    #[inline(always)]
    pub(crate) fn new(org: Vec3, dir: Vec3) -> Self {
        let a = dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        // A zero component gives an infinite reciprocal: a slab the ray runs
        // parallel to yields ±∞ (origin inside / outside) or NaN (origin exactly
        // on a slab plane), and the slab test's selects treat NaN as "no
        // constraint", so a ray lying in a box face still enters the box (the
        // boundary is inclusive). The triangle test uses the exact direction.
        // The six divisions in two 4-lane divides (IEEE-exact per lane, so the
        // values are those of the scalar `safe_inv`, `dir[kx] / dir[kz]`, ...).
        let q = Vec4::ONE / Vec4::new(dir.x, dir.y, dir.z, dir[kz]);
        let s = Vec4::new(dir[kx], dir[ky], 0.0, 0.0) / Vec4::splat(dir[kz]);
        let inv = [q.x, q.y, q.z];
        Self {
            org,
            inv,
            neg: [inv[0] < 0.0, inv[1] < 0.0, inv[2] < 0.0],
            kx,
            ky,
            kz,
            sx: s.x,
            sy: s.y,
            sz: q.w,
        }
    }

    /// Absolute box-range margin (see [`BOX_SLACK`]) for a tree whose
    /// coordinates are at most `scale` in magnitude: the rounding of a hit's `t`
    /// grows with the coordinates' magnitude over the direction's length.
    #[inline(always)]
    pub(crate) fn margin(&self, dir: Vec3, scale: f32) -> f32 {
        (scale + self.org.abs().max_element()) * BOX_SLACK / dir.length()
    }

    /// Entry distance into the node's box if the ray overlaps it within
    /// `[tmin, tmax]`, else `f32::INFINITY`. The near/far slab planes are picked
    /// by the direction's signs; a NaN slab distance (`0 · ∞`, see [`Ray::new`])
    /// fails both selects and so constrains nothing; the far distance is scaled
    /// by `1 + 2γ₃` to stay conservative.
    #[inline(always)]
    pub(crate) fn hit_box(&self, min: &[f32; 3], max: &[f32; 3], tmin: f32, tmax: f32) -> f32 {
        let mut near = tmin;
        let mut far = tmax;
        for k in 0..3 {
            let (lo, hi) = if self.neg[k] {
                (max[k], min[k])
            } else {
                (min[k], max[k])
            };
            let t0 = (lo - self.org[k]) * self.inv[k];
            let t1 = (hi - self.org[k]) * self.inv[k] * BOX_SCALE;
            near = if t0 > near { t0 } else { near };
            far = if t1 < far { t1 } else { far };
        }
        if near <= far {
            near
        } else {
            f32::INFINITY
        }
    }

    /// Watertight ray–triangle test; returns (t, b1, b2) for `tmin < t < tmax`.
    #[inline]
    pub(crate) fn hit_triangle(&self, p: &[Vec3; 3], tmin: f32, tmax: f32) -> Option<(f32, f32, f32)> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let a = p[0] - self.org;
        let b = p[1] - self.org;
        let c = p[2] - self.org;
        let ax = a[kx] - self.sx * a[kz];
        let ay = a[ky] - self.sy * a[kz];
        let bx = b[kx] - self.sx * b[kz];
        let by = b[ky] - self.sy * b[kz];
        let cx = c[kx] - self.sx * c[kz];
        let cy = c[ky] - self.sy * c[kz];
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let (ax, ay, bx, by, cx, cy) = (ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64);
            u = (cx * by - cy * bx) as f32;
            v = (ax * cy - ay * cx) as f32;
            w = (bx * ay - by * ax) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t_scaled = u * (self.sz * a[kz]) + v * (self.sz * b[kz]) + w * (self.sz * c[kz]);
        let rcp = 1.0 / det;
        let t = t_scaled * rcp;
        if t > tmin && t < tmax {
            Some((t, v * rcp, w * rcp))
        } else {
            None
        }
    }
}

/// The watertight ray–triangle test used by the BVH, for brute-force checks:
/// `Some(Hit)` with `triangle: 0` when the ray hits `p` at `tmin < t < tmax`.
pub fn intersect_triangle(p: &[Vec3; 3], origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
    Ray::new(origin, dir)
        .hit_triangle(p, tmin, tmax)
        .map(|(t, b1, b2)| Hit { t, triangle: 0, b1, b2 })
}

/// A BVH over a list of world-space triangles. Triangles with non-finite
/// vertices are left out; zero-area triangles are kept but never hit.
pub struct Bvh {
    pub(crate) nodes: Vec<Node>,
    /// The root: a node or a leaf, with the world bounds (`None` when empty).
    pub(crate) root: Option<(ChildRef, [f32; 3], [f32; 3])>,
    /// Vertex positions in leaf order.
    pub(crate) verts: Vec<[Vec3; 3]>,
    /// Leaf order → index into `triangles`.
    pub(crate) ids: Vec<u32>,
    pub(crate) triangles: Vec<WorldTriangle>,
}

/// Leaf sizes of a build: at most `max` triangles per leaf, and the SAH counts
/// a leaf's intersection cost per `block` triangles (4 for a backend that tests
/// 4 triangles at once).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LeafPolicy {
    pub(crate) max: usize,
    pub(crate) block: usize,
}

impl LeafPolicy {
    /// [`Bvh::build`]: ≤ [`MAX_LEAF`] triangles, cost 1 per triangle.
    pub(crate) const BINARY: LeafPolicy = LeafPolicy {
        max: MAX_LEAF,
        block: 1,
    };
}

struct BuildPrim {
    lo: Vec3,
    hi: Vec3,
    centroid: Vec3,
    id: u32,
}

#[derive(Clone, Copy)]
struct Bin {
    lo: Vec3,
    hi: Vec3,
    count: usize,
}

impl Bin {
    const EMPTY: Bin = Bin {
        lo: Vec3::INFINITY,
        hi: Vec3::NEG_INFINITY,
        count: 0,
    };
}

fn half_area(lo: Vec3, hi: Vec3) -> f32 {
    let d = (hi - lo).max(Vec3::ZERO);
    d.x * d.y + d.y * d.z + d.z * d.x
}

impl Bvh {
    /// Builds the hierarchy (single-threaded, O(n log n)).
    pub fn build(triangles: Vec<WorldTriangle>) -> Self {
        Self::build_impl(triangles, 0.0, LeafPolicy::BINARY)
    }

    /// Like [`Bvh::build`], but first splits the references of triangles whose
    /// boxes are large into up to `extra × triangles` more references with
    /// tighter boxes (pre-splitting, Ernst and Greiner 2007 "Early split
    /// clipping"; priorities and power-of-two grid planes after Karras and Aila
    /// 2013). A triangle can then sit in several leaves: closest-hit and any-hit
    /// answers are unchanged, but [`Bvh::intersect_all`] may list a hit twice, so
    /// only the wide backend (which removes duplicates) builds from this.
    pub(crate) fn build_split(triangles: Vec<WorldTriangle>, extra: f32, policy: LeafPolicy) -> Self {
        Self::build_impl(triangles, extra, policy)
    }

    fn build_impl(triangles: Vec<WorldTriangle>, extra: f32, policy: LeafPolicy) -> Self {
        let mut prims: Vec<BuildPrim> = triangles
            .iter()
            .enumerate()
            .filter(|(_, t)| t.p.iter().all(|p| p.is_finite()))
            .map(|(i, t)| {
                let lo = t.p[0].min(t.p[1]).min(t.p[2]);
                let hi = t.p[0].max(t.p[1]).max(t.p[2]);
                BuildPrim {
                    lo,
                    hi,
                    centroid: 0.5 * (lo + hi),
                    id: i as u32,
                }
            })
            .collect();
        // World bounds from the whole triangles (pre-split boxes are subsets).
        let (mut wlo, mut whi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for p in &prims {
            wlo = wlo.min(p.lo);
            whi = whi.max(p.hi);
        }
        if extra > 0.0 && !prims.is_empty() {
            presplit(&mut prims, &triangles, extra, wlo, whi);
        }
        let mut nodes = Vec::with_capacity(prims.len() / 2 + 1);
        let root = if prims.is_empty() {
            None
        } else {
            let (r, _, _) = build_node(&mut nodes, &mut prims, 0, 0, policy);
            Some((r, wlo.into(), whi.into()))
        };
        let ids: Vec<u32> = prims.iter().map(|p| p.id).collect();
        let verts = ids.iter().map(|&i| triangles[i as usize].p).collect();
        Self {
            nodes,
            root,
            verts,
            ids,
            triangles,
        }
    }

    /// The triangles, in the order given to [`Bvh::build`] (hit indices refer to it).
    pub fn triangles(&self) -> &[WorldTriangle] {
        &self.triangles
    }

    /// Number of interior nodes (each holds both children's boxes).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// World bounds of everything in the hierarchy, or `None` when empty.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.root.map(|(_, lo, hi)| (Vec3::from(lo), Vec3::from(hi)))
    }

    /// Closest hit with `tmin < t < tmax`; ties at equal `t` go to the lowest triangle index.
    pub fn intersect(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut tmax = tmax;
        self.traverse(origin, dir, tmin, &mut tmax, true, |hit, tmax| {
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
        });
        best
    }

    /// Any hit with `tmin < t < tmax` (shadow / visibility rays).
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> bool {
        let mut found = false;
        let mut tmax = tmax;
        self.traverse(origin, dir, tmin, &mut tmax, false, |_, _| {
            found = true;
            true
        });
        found
    }

    /// All hits with `tmin < t < tmax`, sorted by (t, triangle), into `out` (cleared
    /// first). A ray through an edge shared by two triangles may report both.
    pub fn intersect_all(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32, out: &mut Vec<Hit>) {
        out.clear();
        let mut tmax = tmax;
        self.traverse(origin, dir, tmin, &mut tmax, false, |hit, _| {
            out.push(hit);
            false
        });
        out.sort_unstable_by(|a, b| a.t.total_cmp(&b.t).then(a.triangle.cmp(&b.triangle)));
    }

    /// The nearest hit strictly beyond `t_after` (and below `tmax`): step through
    /// the surfaces along a ray one at a time. Surfaces at exactly `t_after` are
    /// skipped, so coplanar duplicates never stall the walk.
    pub fn next_hit(&self, origin: Vec3, dir: Vec3, t_after: f32, tmax: f32) -> Option<Hit> {
        self.intersect(origin, dir, t_after, tmax)
    }

    /// Shared traversal: calls `on_hit(hit, &mut tmax)` for every triangle hit in
    /// range (the callback may shrink `tmax`); stops when it returns true.
    #[inline]
    fn traverse(
        &self,
        origin: Vec3,
        dir: Vec3,
        tmin: f32,
        tmax: &mut f32,
        ordered: bool,
        mut on_hit: impl FnMut(Hit, &mut f32) -> bool,
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
        // Uninitialised: zeroing 1 KiB per ray costs a few percent of throughput.
        let mut stack = [const { MaybeUninit::<(ChildRef, f32)>::uninit() }; STACK];
        let mut sp = 0usize;
        let mut cur = root;
        let mut cur_near = root_near;
        loop {
            if cur_near <= btmax {
                if cur & LEAF != 0 {
                    let first = ((cur & !LEAF) >> 4) as usize;
                    let count = (cur & 15) as usize;
                    for i in first..first + count {
                        if let Some((t, b1, b2)) = ray.hit_triangle(&self.verts[i], tmin, *tmax) {
                            let hit = Hit {
                                t,
                                triangle: self.ids[i],
                                b1,
                                b2,
                            };
                            if on_hit(hit, tmax) {
                                return;
                            }
                            btmax = box_range(tmin, *tmax, margin).1;
                        }
                    }
                } else {
                    let n = &self.nodes[cur as usize];
                    let tl = ray.hit_box(&n.min[0], &n.max[0], btmin, btmax);
                    let tr = ray.hit_box(&n.min[1], &n.max[1], btmin, btmax);
                    let (mut a, mut ta, mut b, mut tb) = (n.child[0], tl, n.child[1], tr);
                    if ordered && tr < tl {
                        std::mem::swap(&mut a, &mut b);
                        std::mem::swap(&mut ta, &mut tb);
                    }
                    if ta < f32::INFINITY {
                        if tb < f32::INFINITY {
                            stack[sp].write((b, tb));
                            sp += 1;
                        }
                        cur = a;
                        cur_near = ta;
                        continue;
                    }
                    if tb < f32::INFINITY {
                        cur = b;
                        cur_near = tb;
                        continue;
                    }
                }
            }
            if sp == 0 {
                return;
            }
            sp -= 1;
            // SAFETY: entries below `sp` were written by the push above.
            (cur, cur_near) = unsafe { stack[sp].assume_init() };
        }
    }

    /// Surface attributes of `hit` for a ray travelling along `dir`.
    pub fn surface(&self, hit: &Hit, dir: Vec3) -> SurfaceHit {
        surface_of(&self.triangles[hit.triangle as usize], hit, dir)
    }
}

/// Surface attributes of `hit` on triangle `tri` for a ray travelling along `dir`.
pub(crate) fn surface_of(tri: &WorldTriangle, hit: &Hit, dir: Vec3) -> SurfaceHit {
    let (b1, b2) = (hit.b1, hit.b2);
    let b0 = 1.0 - b1 - b2;
    let position = tri.p[0] * b0 + tri.p[1] * b1 + tri.p[2] * b2;
    let cross = (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]);
    let geometric_normal = cross.normalize_or_zero();
    let shading = (tri.n[0] * b0 + tri.n[1] * b1 + tri.n[2] * b2).normalize_or_zero();
    let shading_normal = if shading == Vec3::ZERO || !shading.is_finite() {
        geometric_normal
    } else {
        shading
    };
    let uv = [
        tri.uv[0][0] * b0 + tri.uv[1][0] * b1 + tri.uv[2][0] * b2,
        tri.uv[0][1] * b0 + tri.uv[1][1] * b1 + tri.uv[2][1] * b2,
    ];
    SurfaceHit {
        t: hit.t,
        triangle: hit.triangle,
        position,
        geometric_normal,
        shading_normal,
        front_face: cross.dot(dir) < 0.0,
        uv,
        material: tri.material,
        object: tri.object,
    }
}

/// Largest coordinate magnitude of a box.
#[inline(always)]
pub(crate) fn scale_of(lo: &[f32; 3], hi: &[f32; 3]) -> f32 {
    Vec3::from(*lo).abs().max(Vec3::from(*hi).abs()).max_element()
}

/// The smallest float greater than finite `x`.
pub(crate) fn next_up(x: f32) -> f32 {
    if x == 0.0 {
        f32::from_bits(1)
    } else if x > 0.0 {
        f32::from_bits(x.to_bits() + 1)
    } else {
        f32::from_bits(x.to_bits() - 1)
    }
}

/// Recursively builds the subtree over `prims` (which start at `offset` in leaf
/// order), appending interior nodes depth-first and reordering `prims` into
/// leaf order. Returns the subtree's reference and bounds.
fn build_node(
    nodes: &mut Vec<Node>,
    prims: &mut [BuildPrim],
    offset: usize,
    depth: usize,
    policy: LeafPolicy,
) -> (ChildRef, Vec3, Vec3) {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let (mut clo, mut chi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in prims.iter() {
        lo = lo.min(p.lo);
        hi = hi.max(p.hi);
        clo = clo.min(p.centroid);
        chi = chi.max(p.centroid);
    }
    let n = prims.len();
    // Built only where a leaf is returned: `leaf_ref` debug-asserts n ≤ 15.
    let leaf = || (leaf_ref(offset, n), lo, hi);
    if n <= 1 {
        return leaf();
    }
    let split = if depth > MAX_SAH_DEPTH {
        None
    } else {
        sah_split(prims, lo, hi, clo, chi, policy)
    };
    let mid = match split {
        Some(None) => return leaf(), // SAH prefers a leaf and it is small enough
        Some(Some(mid)) => mid,
        None => {
            if n <= policy.max {
                return leaf();
            }
            // Median split along the widest centroid axis (degenerate centroids
            // or deep recursion): always balanced, so depth stays logarithmic.
            let axis = (chi - clo).max_position();
            prims.select_nth_unstable_by(n / 2, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
            n / 2
        }
    };
    let index = nodes.len();
    nodes.push(Node {
        min: [[0.0; 3]; 2],
        max: [[0.0; 3]; 2],
        child: [0; 2],
    });
    let (left, right) = prims.split_at_mut(mid);
    let (l, llo, lhi) = build_node(nodes, left, offset, depth + 1, policy);
    let (r, rlo, rhi) = build_node(nodes, right, offset + mid, depth + 1, policy);
    nodes[index] = Node {
        min: [llo.into(), rlo.into()],
        max: [lhi.into(), rhi.into()],
        child: [l, r],
    };
    (index as ChildRef, lo, hi)
}

/// Binned SAH over centroids. `None`: no usable split (degenerate centroids);
/// `Some(None)`: make a leaf; `Some(Some(mid))`: prims partitioned at `mid`.
fn sah_split(
    prims: &mut [BuildPrim],
    lo: Vec3,
    hi: Vec3,
    clo: Vec3,
    chi: Vec3,
    policy: LeafPolicy,
) -> Option<Option<usize>> {
    let blocks = |n: usize| n.div_ceil(policy.block) as f32;
    let n = prims.len();
    let extent = chi - clo;
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, bin)
    for axis in 0..3 {
        if !(extent[axis] > 0.0) {
            continue;
        }
        let scale = BINS as f32 / extent[axis];
        let bin_of = |c: f32| (((c - clo[axis]) * scale) as usize).min(BINS - 1);
        let mut bins = [Bin::EMPTY; BINS];
        for p in prims.iter() {
            let b = &mut bins[bin_of(p.centroid[axis])];
            b.lo = b.lo.min(p.lo);
            b.hi = b.hi.max(p.hi);
            b.count += 1;
        }
        // Sweep from the right to get right-side areas, then from the left.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0usize; BINS];
        let (mut rlo, mut rhi, mut rc) = (Vec3::INFINITY, Vec3::NEG_INFINITY, 0);
        for i in (1..BINS).rev() {
            rlo = rlo.min(bins[i].lo);
            rhi = rhi.max(bins[i].hi);
            rc += bins[i].count;
            right_area[i] = half_area(rlo, rhi);
            right_count[i] = rc;
        }
        let (mut llo, mut lhi, mut lc) = (Vec3::INFINITY, Vec3::NEG_INFINITY, 0);
        for i in 0..BINS - 1 {
            llo = llo.min(bins[i].lo);
            lhi = lhi.max(bins[i].hi);
            lc += bins[i].count;
            let rc = right_count[i + 1];
            if lc == 0 || rc == 0 {
                continue;
            }
            let cost = blocks(lc) * half_area(llo, lhi) + blocks(rc) * right_area[i + 1];
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, axis, i + 1));
            }
        }
    }
    let (cost, axis, split_bin) = best?;
    // Costs relative to the parent's area: traversal 1, intersection 1 per triangle.
    let parent = half_area(lo, hi).max(f32::MIN_POSITIVE);
    let split_cost = 1.0 + cost / parent;
    if n <= policy.max && split_cost >= blocks(n) {
        return Some(None);
    }
    let scale = BINS as f32 / extent[axis];
    let mut mid = 0;
    for i in 0..n {
        let b = (((prims[i].centroid[axis] - clo[axis]) * scale) as usize).min(BINS - 1);
        if b < split_bin {
            prims.swap(i, mid);
            mid += 1;
        }
    }
    if mid == 0 || mid == n {
        return None;
    }
    Some(Some(mid))
}

/// Pre-splitting of triangle references (see [`Bvh::build_split`]): the
/// reference whose box has the largest surface area not explained by its
/// triangle is split at a power-of-two grid plane of the scene bounds across its
/// longest axis; each half gets the box of the triangle's part on that side,
/// clipped to the half (and widened by a few ulps so rounding never loses a
/// piece of the triangle). Stops at `extra × n` new references.
fn presplit(prims: &mut Vec<BuildPrim>, triangles: &[WorldTriangle], extra: f32, wlo: Vec3, whi: Vec3) {
    use std::cmp::Ordering;
    use std::collections::BinaryHeap;

    struct Item {
        priority: f32,
        index: usize,
    }
    impl PartialEq for Item {
        fn eq(&self, o: &Self) -> bool {
            self.cmp(o) == Ordering::Equal
        }
    }
    impl Eq for Item {}
    impl PartialOrd for Item {
        fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
            Some(self.cmp(o))
        }
    }
    impl Ord for Item {
        fn cmp(&self, o: &Self) -> Ordering {
            self.priority.total_cmp(&o.priority).then(o.index.cmp(&self.index))
        }
    }

    let budget = (prims.len() as f64 * extra as f64).min(1e8) as usize;
    let tri_area = |id: u32| {
        let p = &triangles[id as usize].p;
        0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
    };
    // Wasted box area: the box's half surface area minus the triangle's area
    // (a flat, axis-aligned triangle filling its box wastes nothing).
    let priority = |p: &BuildPrim, area: f32| {
        let w = half_area(p.lo, p.hi) - area.min(half_area(p.lo, p.hi));
        if w.is_finite() {
            w
        } else {
            0.0
        }
    };
    let areas: Vec<f32> = prims.iter().map(|p| tri_area(p.id)).collect();
    let mut heap: BinaryHeap<Item> = prims
        .iter()
        .enumerate()
        .map(|(i, p)| Item {
            priority: priority(p, areas[i]),
            index: i,
        })
        .collect();
    let mut ref_area = areas;
    let mut added = 0;
    let extent = whi - wlo;
    while added < budget {
        let Some(item) = heap.pop() else { break };
        if !(item.priority > 0.0) {
            break;
        }
        let p = &prims[item.index];
        let axis = (p.hi - p.lo).max_position();
        let Some(plane) = grid_plane(wlo[axis], extent[axis], p.lo[axis], p.hi[axis]) else {
            continue; // too thin to split: leave it out of the heap
        };
        let tri = &triangles[p.id as usize].p;
        let (Some((llo, lhi)), Some((rlo, rhi))) = (
            clip_box(tri, axis, plane, true, p.lo, p.hi),
            clip_box(tri, axis, plane, false, p.lo, p.hi),
        ) else {
            continue;
        };
        let id = p.id;
        // Each piece's share of the triangle's area, by box area (priority only).
        let total = ref_area[item.index];
        let (la, ra) = (half_area(llo, lhi), half_area(rlo, rhi));
        let lshare = if la + ra > 0.0 {
            total * la / (la + ra)
        } else {
            0.5 * total
        };
        prims[item.index] = BuildPrim {
            lo: llo,
            hi: lhi,
            centroid: 0.5 * (llo + lhi),
            id,
        };
        ref_area[item.index] = lshare;
        prims.push(BuildPrim {
            lo: rlo,
            hi: rhi,
            centroid: 0.5 * (rlo + rhi),
            id,
        });
        ref_area.push(total - lshare);
        let n = prims.len() - 1;
        heap.push(Item {
            priority: priority(&prims[item.index], ref_area[item.index]),
            index: item.index,
        });
        heap.push(Item {
            priority: priority(&prims[n], ref_area[n]),
            index: n,
        });
        added += 1;
    }
}

/// The coarsest plane `lo + k·extent/2^m` strictly inside `(a, b)`, if any.
fn grid_plane(lo: f32, extent: f32, a: f32, b: f32) -> Option<f32> {
    if !(extent > 0.0) || !(b > a) {
        return None;
    }
    let mut cell = extent;
    for _ in 0..24 {
        cell *= 0.5;
        let k = ((b - lo) / cell).floor();
        let plane = lo + k * cell;
        if plane > a && plane < b {
            return Some(plane);
        }
        if plane <= a && lo + (k + 1.0) * cell < b && lo + (k + 1.0) * cell > a {
            return Some(lo + (k + 1.0) * cell);
        }
    }
    // Fall back to the midpoint when the grid is too coarse near this box.
    let mid = 0.5 * (a + b);
    (mid > a && mid < b).then_some(mid)
}

/// Box of the part of triangle `p` on one side of the plane `x[axis] = plane`
/// (`below`: `≤ plane`), intersected with the box `[lo, hi]`, or `None` when
/// that part is empty. Edge–plane crossings are rounded, so the box is widened
/// by a few ulps (relative) before the intersection: it always contains the
/// exact part.
fn clip_box(p: &[Vec3; 3], axis: usize, plane: f32, below: bool, lo: Vec3, hi: Vec3) -> Option<(Vec3, Vec3)> {
    let inside = |v: Vec3| if below { v[axis] <= plane } else { v[axis] >= plane };
    let (mut blo, mut bhi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for i in 0..3 {
        let (a, b) = (p[i], p[(i + 1) % 3]);
        if inside(a) {
            blo = blo.min(a);
            bhi = bhi.max(a);
        }
        if (a[axis] < plane && b[axis] > plane) || (a[axis] > plane && b[axis] < plane) {
            let s = (plane - a[axis]) / (b[axis] - a[axis]);
            let mut x = a + (b - a) * s;
            x[axis] = plane;
            blo = blo.min(x);
            bhi = bhi.max(x);
        }
    }
    if !(blo.x <= bhi.x) {
        return None;
    }
    // Widen by 2⁻¹⁸ of the magnitude plus the box size (crossings carry a few
    // roundings), then keep within the parent box.
    let pad = (blo.abs().max(bhi.abs()) + (hi - lo)) * (1.0 / 262_144.0);
    let mut nlo = (blo - pad).max(lo);
    let mut nhi = (bhi + pad).min(hi);
    if below {
        nhi[axis] = nhi[axis].min(plane);
    } else {
        nlo[axis] = nlo[axis].max(plane);
    }
    let valid = nlo.x <= nhi.x && nlo.y <= nhi.y && nlo.z <= nhi.z && nlo.is_finite() && nhi.is_finite();
    if !valid {
        return None;
    }
    Some((nlo, nhi))
}
