//! CPU mirror of `shaders/common/packing.wgsl` (Oct16 normals), for tests and read-back.

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

/// Quantises to two UNORM8 values as the GPU's Rgba8Unorm target does.
pub fn oct16_pack(n: Vec3) -> [u8; 2] {
    let e = oct_encode(n);
    [
        (e.x.clamp(0.0, 1.0) * 255.0).round() as u8,
        (e.y.clamp(0.0, 1.0) * 255.0).round() as u8,
    ]
}

pub fn oct16_unpack(b: [u8; 2]) -> Vec3 {
    oct_decode(Vec2::new(b[0] as f32 / 255.0, b[1] as f32 / 255.0))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Oct16 round trip: worst angular error over a dense sphere sweep stays under 1.5°.
    #[test]
    fn oct16_round_trip_error_bound() {
        let mut worst: f32 = 0.0;
        for i in 0..200 {
            for j in 0..400 {
                let th = std::f32::consts::PI * (i as f32 + 0.5) / 200.0;
                let ph = std::f32::consts::TAU * j as f32 / 400.0;
                let n = Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                let r = oct16_unpack(oct16_pack(n));
                worst = worst.max(n.dot(r).clamp(-1.0, 1.0).acos().to_degrees());
                // unquantised round trip is exact to float precision
                assert!(n.dot(oct_decode(oct_encode(n))) > 1.0 - 1e-5);
            }
        }
        assert!(worst < 1.5, "worst Oct16 error {worst}°");
    }
}
