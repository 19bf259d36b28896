//! Octahedral mapping of unit vectors to [0, 1]² (the G-buffer's Oct16 normals,
//! `shaders/common/packing.wgsl`, and the light probes' distance maps).

use glam::{Vec2, Vec3};

/// Unit vector → [0,1]² octahedral coordinates (store each in 8 bits for Oct16).
pub fn oct_encode(n: Vec3) -> Vec2 {
    let mut p = Vec2::new(n.x, n.y) / (n.x.abs() + n.y.abs() + n.z.abs());
    if n.z < 0.0 {
        p = Vec2::new(
            (1.0 - p.y.abs()) * p.x.signum_nonzero(),
            (1.0 - p.x.abs()) * p.y.signum_nonzero(),
        );
    }
    p * 0.5 + 0.5
}

/// [0,1]² octahedral coordinates → unit vector.
pub fn oct_decode(e: Vec2) -> Vec3 {
    let f = e * 2.0 - 1.0;
    let mut n = Vec3::new(f.x, f.y, 1.0 - f.x.abs() - f.y.abs());
    let t = (-n.z).clamp(0.0, 1.0);
    n.x += if n.x >= 0.0 { -t } else { t };
    n.y += if n.y >= 0.0 { -t } else { t };
    n.normalize()
}

trait SignumNonZero {
    fn signum_nonzero(self) -> f32;
}
impl SignumNonZero for f32 {
    /// Like WGSL's `select(-1, 1, v >= 0)`.
    fn signum_nonzero(self) -> f32 {
        if self >= 0.0 {
            1.0
        } else {
            -1.0
        }
    }
}
