//! CPU mirror of `shaders/common/packing.wgsl` (Oct16 normals), for tests and read-back.

use glam::{Vec2, Vec3};

pub use strata_scene::oct::{oct_decode, oct_encode};

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
