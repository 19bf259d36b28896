//! Occlusion rays in *bundles*: up to 8 rays that share one origin and whose
//! directions lie in one octant (every component non-zero, the same sign per
//! axis), traced through the [`WideBvh`] together. An AO pixel casts hundreds
//! to thousands of such rays from one point; sorted by direction (see
//! [`crate::ao`]), a bundle of 8 spans a narrow cone.
//!
//! - **Interior nodes** are tested once per bundle with *interval arithmetic*
//!   over the bundle's reciprocal directions (Boulos et al. 2007, "Geometric
//!   and arithmetic culling methods for entire ray packets"): per axis the
//!   slab distances of all rays lie between `(plane − o) · inv_lo` and
//!   `(plane − o) · inv_hi`, and IEEE multiplication is monotone in each
//!   factor, so taking the smallest entry and the largest exit over the
//!   bundle's reciprocals gives a box test that passes whenever *any* ray's own
//!   slab test ([`crate::bvh::Ray::hit_box`], same rounding) passes.
//! - **Leaves** are culled per ray: the leaf's box from its parent node is
//!   tested against the 8 rays in the 8 AVX lanes with exactly the operations
//!   of the single-ray test, and only rays that pass test the leaf's
//!   triangles, each with its own watertight test ([`crate::wide`]'s
//!   `hit_packet`).
//! - A ray leaves the bundle at its first hit; the bundle is done when every
//!   ray has hit or the stack is empty.
//!
//! Whatever the bundle visits, each ray's answer is whether one of its own
//! exact triangle tests found a hit in `(tmin, tmax)`, and every leaf its own
//! traversal would test is still tested (the bundle's tests are conservative),
//! so [`WideBvh::occluded_bundle`] returns bit for bit what
//! [`WideBvh::occluded`] returns ray by ray (tested in
//! `tests/reference/tracer.rs`). Bundles that do not qualify (mixed octants, a
//! zero or non-finite component, a root leaf, no AVX) are traced ray by ray.

use glam::Vec3;

use crate::bvh::{box_range, scale_of, ChildRef, Ray, LEAF};
use crate::wide::{WideBvh, WIDTH};

/// Most rays in one bundle (one AVX register of lanes).
pub const BUNDLE: usize = 8;

/// True when `dirs` may be traced as one bundle: every component finite and
/// non-zero, with the same sign per axis for every ray.
pub fn same_octant(dirs: &[Vec3]) -> bool {
    let Some(first) = dirs.first() else {
        return false;
    };
    let sign = first.cmplt(Vec3::ZERO).bitmask();
    dirs.iter()
        .all(|d| d.is_finite() && d.cmpne(Vec3::ZERO).all() && d.cmplt(Vec3::ZERO).bitmask() == sign)
}

impl WideBvh {
    /// Occlusion of up to [`BUNDLE`] rays from `origin`: bit `i` is set when
    /// ray `dirs[i]` has a hit with `tmin < t < tmax`. The same answers as
    /// [`WideBvh::occluded`] per ray, bit for bit (see the module docs).
    ///
    /// # Panics
    /// When `dirs` holds more than [`BUNDLE`] rays.
    pub fn occluded_bundle(&self, origin: Vec3, dirs: &[Vec3], tmin: f32, tmax: f32) -> u32 {
        assert!(dirs.len() <= BUNDLE, "a bundle holds at most {BUNDLE} rays");
        #[cfg(target_arch = "x86_64")]
        if self.avx
            && dirs.len() > 1
            && tmin <= tmax
            && origin.is_finite()
            && same_octant(dirs)
            && self.root.is_some_and(|(r, _, _)| r & LEAF == 0)
        {
            // SAFETY: `avx` is only true when the CPU reports AVX.
            return unsafe { self.bundle_avx(origin, dirs, tmin, tmax) };
        }
        dirs.iter()
            .enumerate()
            .fold(0, |m, (i, &d)| m | (self.occluded(origin, d, tmin, tmax) as u32) << i)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn bundle_avx(&self, origin: Vec3, dirs: &[Vec3], tmin: f32, tmax: f32) -> u32 {
        use std::mem::MaybeUninit;
        let Some((root, root_min, root_max)) = self.root else {
            return 0;
        };
        let n = dirs.len();
        let valid = (1u32 << n) - 1;
        // Lanes past `n` repeat the last ray (their bits are never reported).
        let mut rays = [Ray::new(origin, dirs[n - 1]); BUNDLE];
        for (ray, &d) in rays.iter_mut().zip(&dirs[..n - 1]) {
            *ray = Ray::new(origin, d);
        }
        let scale = scale_of(&root_min, &root_max);
        let mut lanes = Lanes {
            org: [origin.x, origin.y, origin.z],
            neg: rays[0].neg,
            inv: [[0.0; BUNDLE]; 3],
            tmin: [0.0; BUNDLE],
            tmax: [0.0; BUNDLE],
        };
        for (i, ray) in rays.iter().enumerate() {
            for k in 0..3 {
                lanes.inv[k][i] = ray.inv[k];
            }
            let (lo, hi) = box_range(tmin, tmax, ray.margin(dirs[i.min(n - 1)], scale));
            (lanes.tmin[i], lanes.tmax[i]) = (lo, hi);
        }
        let mut interval = Interval::of(&lanes, valid);
        let mut stack = [const { MaybeUninit::<(ChildRef, u32)>::uninit() }; crate::wide::STACK];
        let mut sp = 0usize;
        let (mut cur, mut mask) = (root, valid);
        let mut hits = 0u32;
        loop {
            if cur & LEAF != 0 {
                let first = ((cur & !LEAF) >> 4) as usize;
                let total = (cur & 15) as usize;
                let mut m = mask & !hits;
                while m != 0 {
                    let lane = m.trailing_zeros() as usize;
                    m &= m - 1;
                    for index in first..first + total.div_ceil(4) {
                        let count = (total - 4 * (index - first)).min(4);
                        let pk = &self.packets[index];
                        if crate::wide::hit_packet(pk, count, &rays[lane], tmin, tmax).0 != 0 {
                            hits |= 1 << lane;
                            break;
                        }
                    }
                }
                let active = valid & !hits;
                if active == 0 {
                    return hits;
                }
                if active != interval.rays {
                    interval = Interval::of(&lanes, active);
                }
            } else {
                let node = &self.nodes[cur as usize];
                // SAFETY: AVX is enabled on this function.
                let mut children = unsafe { interval_box8(node, &lanes, &interval) };
                let active = valid & !hits;
                let mut next: Option<(ChildRef, u32)> = None;
                while children != 0 {
                    let i = children.trailing_zeros() as usize;
                    children &= children - 1;
                    let child = node.child[i];
                    let m = if child & LEAF != 0 {
                        // SAFETY: AVX is enabled on this function.
                        active & unsafe { rays_box(node, i, &lanes) }
                    } else {
                        active
                    };
                    if m == 0 {
                        continue;
                    }
                    if next.is_none() {
                        next = Some((child, m));
                    } else {
                        self.prefetch(child);
                        stack[sp].write((child, m));
                        sp += 1;
                    }
                }
                if let Some((c, m)) = next {
                    (cur, mask) = (c, m);
                    continue;
                }
            }
            loop {
                if sp == 0 {
                    return hits;
                }
                sp -= 1;
                // SAFETY: entries below `sp` were written by the pushes above.
                let (c, m) = unsafe { stack[sp].assume_init() };
                let m = m & !hits;
                if m != 0 {
                    (cur, mask) = (c, m);
                    break;
                }
            }
        }
    }
}

/// The bundle's rays as structure of arrays: reciprocal directions and the
/// box-test range of each ray (`box_range` with its own margin).
struct Lanes {
    org: [f32; 3],
    /// Direction signs, shared by every ray of the bundle.
    neg: [bool; 3],
    inv: [[f32; BUNDLE]; 3],
    tmin: [f32; BUNDLE],
    tmax: [f32; BUNDLE],
}

/// Interval bounds over the rays in `rays`: the smallest and largest
/// reciprocal per axis and the widest box-test range.
struct Interval {
    rays: u32,
    inv_lo: [f32; 3],
    inv_hi: [f32; 3],
    tmin: f32,
    tmax: f32,
}

impl Interval {
    fn of(lanes: &Lanes, rays: u32) -> Self {
        let mut iv = Interval {
            rays,
            inv_lo: [f32::INFINITY; 3],
            inv_hi: [f32::NEG_INFINITY; 3],
            tmin: f32::INFINITY,
            tmax: f32::NEG_INFINITY,
        };
        let mut m = rays;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            for k in 0..3 {
                iv.inv_lo[k] = iv.inv_lo[k].min(lanes.inv[k][i]);
                iv.inv_hi[k] = iv.inv_hi[k].max(lanes.inv[k][i]);
            }
            iv.tmin = iv.tmin.min(lanes.tmin[i]);
            iv.tmax = iv.tmax.max(lanes.tmax[i]);
        }
        iv
    }
}

/// The interval-arithmetic slab test on a node's 8 children (bit i: child i
/// may be entered by some ray of the bundle). Per axis, the entry distance
/// `(near − o) · inv` is smallest at `inv_lo` when `near − o ≥ 0` and at
/// `inv_hi` otherwise; the exit `(far − o) · inv · (1 + 2γ₃)` is largest at
/// `inv_hi` when `far − o ≥ 0` and at `inv_lo` otherwise (the directions share
/// their signs and are non-zero, so no NaN arises; empty slots give +∞/−∞).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
unsafe fn interval_box8(node: &crate::wide::Node8, lanes: &Lanes, iv: &Interval) -> u32 {
    use std::arch::x86_64::*;
    let mut near = _mm256_set1_ps(iv.tmin);
    let mut far = _mm256_set1_ps(iv.tmax);
    let scale = _mm256_set1_ps(crate::bvh::BOX_SCALE);
    let zero = _mm256_setzero_ps();
    for k in 0..3 {
        let (lo, hi) = if lanes.neg[k] {
            (&node.hi[k], &node.lo[k])
        } else {
            (&node.lo[k], &node.hi[k])
        };
        let o = _mm256_set1_ps(lanes.org[k]);
        let (inv_lo, inv_hi) = (_mm256_set1_ps(iv.inv_lo[k]), _mm256_set1_ps(iv.inv_hi[k]));
        // SAFETY: 32 readable bytes each (`[f32; 8]`); unaligned loads.
        let (a, b) = unsafe {
            (
                _mm256_sub_ps(_mm256_loadu_ps(lo.as_ptr()), o),
                _mm256_sub_ps(_mm256_loadu_ps(hi.as_ptr()), o),
            )
        };
        // blendv(x, y, m) takes y where m is set.
        let inv_near = _mm256_blendv_ps(inv_hi, inv_lo, _mm256_cmp_ps::<_CMP_GE_OQ>(a, zero));
        let inv_far = _mm256_blendv_ps(inv_lo, inv_hi, _mm256_cmp_ps::<_CMP_GE_OQ>(b, zero));
        let t0 = _mm256_mul_ps(a, inv_near);
        let t1 = _mm256_mul_ps(_mm256_mul_ps(b, inv_far), scale);
        near = _mm256_max_ps(t0, near);
        far = _mm256_min_ps(t1, far);
    }
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32
}

/// Child `c`'s box against every ray of the bundle, one ray per lane, with
/// exactly the operations (and so the results) of the single-ray test.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
unsafe fn rays_box(node: &crate::wide::Node8, c: usize, lanes: &Lanes) -> u32 {
    use std::arch::x86_64::*;
    debug_assert!(c < WIDTH);
    // SAFETY: 32 readable bytes each (`[f32; 8]`); unaligned loads.
    let (mut near, mut far) = unsafe {
        (
            _mm256_loadu_ps(lanes.tmin.as_ptr()),
            _mm256_loadu_ps(lanes.tmax.as_ptr()),
        )
    };
    let scale = _mm256_set1_ps(crate::bvh::BOX_SCALE);
    for k in 0..3 {
        let (lo, hi) = if lanes.neg[k] {
            (node.hi[k][c], node.lo[k][c])
        } else {
            (node.lo[k][c], node.hi[k][c])
        };
        let o = _mm256_set1_ps(lanes.org[k]);
        // SAFETY: as above.
        let inv = unsafe { _mm256_loadu_ps(lanes.inv[k].as_ptr()) };
        let t0 = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(lo), o), inv);
        let t1 = _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(hi), o), inv), scale);
        near = _mm256_max_ps(t0, near);
        far = _mm256_min_ps(t1, far);
    }
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32
}
