//! The ray-tracing interface of the reference and its backends.
//!
//! Every backend answers the same four queries with the same semantics, so the
//! oracles do not depend on which one runs:
//!
//! - [`Tracer::intersect`]: the closest hit with `tmin < t < tmax`; ties at equal
//!   `t` go to the lowest triangle index;
//! - [`Tracer::occluded`]: whether any hit with `tmin < t < tmax` exists;
//! - [`Tracer::intersect_all`]: every hit in range, sorted by `(t, triangle)`;
//! - [`Tracer::surface`]: the surface attributes of a hit.
//!
//! All use the watertight ray–triangle test of Woop, Benthin and Wald (JCGT
//! 2013), so a ray through a shared edge or vertex of a closed mesh never slips
//! through, and every backend computes bitwise the same `t` and barycentrics
//! for a given (ray, triangle) pair; the hit sets do not depend on the tree (box
//! tests are conservative, see [`crate::bvh::BOX_SLACK`]), so the answers are
//! identical across backends (tested ray by ray).
//!
//! Backends ([`TracerKind`]):
//! - [`TracerKind::Binary`]: the binned-SAH binary [`Bvh`] (one box pair per node);
//! - [`TracerKind::Wide`] (default): the same tree collapsed to 8 children per node,
//!   8 boxes and 4 triangles tested per step with SIMD ([`WideBvh`]).

use glam::Vec3;
use strata_scene::WorldTriangle;

use crate::bvh::{Bvh, Hit, SurfaceHit};
use crate::wide::WideBvh;

/// A ray tracer over a fixed list of world-space triangles. `t` is measured in
/// units of the ray direction as given (directions need not be normalised).
pub trait Tracer: Send + Sync {
    /// Closest hit with `tmin < t < tmax`; ties at equal `t` go to the lowest triangle index.
    fn intersect(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Option<Hit>;

    /// Any hit with `tmin < t < tmax` (shadow / visibility rays).
    fn occluded(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> bool;

    /// Occlusion of up to [`crate::bundle::BUNDLE`] rays sharing `origin`: bit
    /// `i` is set when `dirs[i]` has a hit with `tmin < t < tmax`. Always the
    /// same answers as [`Tracer::occluded`] ray by ray; backends may trace the
    /// rays together ([`crate::bundle`]).
    fn occluded_bundle(&self, origin: Vec3, dirs: &[Vec3], tmin: f32, tmax: f32) -> u32 {
        dirs.iter()
            .enumerate()
            .fold(0, |m, (i, &d)| m | (self.occluded(origin, d, tmin, tmax) as u32) << i)
    }

    /// All hits with `tmin < t < tmax`, sorted by (t, triangle), into `out`
    /// (cleared first). A ray through an edge shared by two triangles may report both.
    fn intersect_all(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32, out: &mut Vec<Hit>);

    /// The nearest hit strictly beyond `t_after` (and below `tmax`).
    fn next_hit(&self, origin: Vec3, dir: Vec3, t_after: f32, tmax: f32) -> Option<Hit> {
        self.intersect(origin, dir, t_after, tmax)
    }

    /// The triangles, in the order given at build time (hit indices refer to it).
    fn triangles(&self) -> &[WorldTriangle];

    /// World bounds of everything traced, or `None` when empty.
    fn bounds(&self) -> Option<(Vec3, Vec3)>;

    /// Surface attributes of `hit` for a ray travelling along `dir`.
    fn surface(&self, hit: &Hit, dir: Vec3) -> SurfaceHit {
        crate::bvh::surface_of(&self.triangles()[hit.triangle as usize], hit, dir)
    }

    /// Interior nodes of the acceleration structure.
    fn node_count(&self) -> usize;
}

impl Tracer for Bvh {
    fn intersect(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        Bvh::intersect(self, origin, dir, tmin, tmax)
    }
    fn occluded(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> bool {
        Bvh::occluded(self, origin, dir, tmin, tmax)
    }
    fn intersect_all(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32, out: &mut Vec<Hit>) {
        Bvh::intersect_all(self, origin, dir, tmin, tmax, out)
    }
    fn triangles(&self) -> &[WorldTriangle] {
        Bvh::triangles(self)
    }
    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        Bvh::bounds(self)
    }
    fn node_count(&self) -> usize {
        Bvh::node_count(self)
    }
}

impl Tracer for WideBvh {
    fn intersect(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        WideBvh::intersect(self, origin, dir, tmin, tmax)
    }
    fn occluded(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> bool {
        WideBvh::occluded(self, origin, dir, tmin, tmax)
    }
    fn occluded_bundle(&self, origin: Vec3, dirs: &[Vec3], tmin: f32, tmax: f32) -> u32 {
        WideBvh::occluded_bundle(self, origin, dirs, tmin, tmax)
    }
    fn intersect_all(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32, out: &mut Vec<Hit>) {
        WideBvh::intersect_all(self, origin, dir, tmin, tmax, out)
    }
    fn triangles(&self) -> &[WorldTriangle] {
        WideBvh::triangles(self)
    }
    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        WideBvh::bounds(self)
    }
    fn node_count(&self) -> usize {
        WideBvh::node_count(self)
    }
}

/// Which backend a [`crate::Reference`] traces with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TracerKind {
    /// Binned-SAH binary BVH, scalar traversal.
    Binary,
    /// The binary tree collapsed to 8-wide nodes, SIMD box and triangle tests.
    #[default]
    Wide,
}

impl TracerKind {
    /// Every backend, default first.
    pub const ALL: [TracerKind; 2] = [TracerKind::Wide, TracerKind::Binary];

    /// Short name (`"wide"`, `"binary"`), as used on command lines and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            TracerKind::Binary => "binary",
            TracerKind::Wide => "wide",
        }
    }

    /// Parses [`TracerKind::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// A built backend: static dispatch over [`TracerKind`]. Its inherent methods
/// are those of [`Tracer`], so callers need not import the trait.
pub enum AnyTracer {
    Binary(Bvh),
    Wide(WideBvh),
}

macro_rules! dispatch {
    ($self:ident, $b:ident => $e:expr) => {
        match $self {
            AnyTracer::Binary($b) => $e,
            AnyTracer::Wide($b) => $e,
        }
    };
}

impl AnyTracer {
    /// Builds the `kind` backend over `triangles`.
    pub fn build(triangles: Vec<WorldTriangle>, kind: TracerKind) -> Self {
        match kind {
            TracerKind::Binary => AnyTracer::Binary(Bvh::build(triangles)),
            TracerKind::Wide => AnyTracer::Wide(WideBvh::build(triangles)),
        }
    }

    /// The `kind` backend from an already built binary tree (which every
    /// backend starts from).
    pub fn from_binary(bvh: Bvh, kind: TracerKind) -> Self {
        match kind {
            TracerKind::Binary => AnyTracer::Binary(bvh),
            TracerKind::Wide => AnyTracer::Wide(WideBvh::from_binary(bvh)),
        }
    }

    pub fn kind(&self) -> TracerKind {
        match self {
            AnyTracer::Binary(_) => TracerKind::Binary,
            AnyTracer::Wide(_) => TracerKind::Wide,
        }
    }

    /// See [`Tracer::intersect`].
    #[inline]
    pub fn intersect(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        dispatch!(self, b => b.intersect(origin, dir, tmin, tmax))
    }

    /// See [`Tracer::occluded`].
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> bool {
        dispatch!(self, b => b.occluded(origin, dir, tmin, tmax))
    }

    /// See [`Tracer::occluded_bundle`].
    #[inline]
    pub fn occluded_bundle(&self, origin: Vec3, dirs: &[Vec3], tmin: f32, tmax: f32) -> u32 {
        dispatch!(self, b => Tracer::occluded_bundle(b, origin, dirs, tmin, tmax))
    }

    /// See [`Tracer::intersect_all`].
    #[inline]
    pub fn intersect_all(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32, out: &mut Vec<Hit>) {
        dispatch!(self, b => b.intersect_all(origin, dir, tmin, tmax, out))
    }

    /// See [`Tracer::next_hit`].
    #[inline]
    pub fn next_hit(&self, origin: Vec3, dir: Vec3, t_after: f32, tmax: f32) -> Option<Hit> {
        self.intersect(origin, dir, t_after, tmax)
    }

    /// See [`Tracer::surface`].
    #[inline]
    pub fn surface(&self, hit: &Hit, dir: Vec3) -> SurfaceHit {
        crate::bvh::surface_of(&self.triangles()[hit.triangle as usize], hit, dir)
    }

    /// See [`Tracer::triangles`].
    pub fn triangles(&self) -> &[WorldTriangle] {
        dispatch!(self, b => b.triangles())
    }

    /// See [`Tracer::bounds`].
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        dispatch!(self, b => b.bounds())
    }

    /// See [`Tracer::node_count`].
    pub fn node_count(&self) -> usize {
        dispatch!(self, b => b.node_count())
    }
}

impl Tracer for AnyTracer {
    fn intersect(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        AnyTracer::intersect(self, origin, dir, tmin, tmax)
    }
    fn occluded(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> bool {
        AnyTracer::occluded(self, origin, dir, tmin, tmax)
    }
    fn occluded_bundle(&self, origin: Vec3, dirs: &[Vec3], tmin: f32, tmax: f32) -> u32 {
        AnyTracer::occluded_bundle(self, origin, dirs, tmin, tmax)
    }
    fn intersect_all(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32, out: &mut Vec<Hit>) {
        AnyTracer::intersect_all(self, origin, dir, tmin, tmax, out)
    }
    fn triangles(&self) -> &[WorldTriangle] {
        AnyTracer::triangles(self)
    }
    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        AnyTracer::bounds(self)
    }
    fn node_count(&self) -> usize {
        AnyTracer::node_count(self)
    }
}
