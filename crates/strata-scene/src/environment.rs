//! A radiance environment map: DGB §3.6's fallback for mirror-reflection rays that leave
//! the guard band or go their maximum distance ("we revert to mirror reflection
//! environment map lookups"). A cube map of the radiance arriving at one point, baked by
//! the CPU path tracer (`strata_reference`) and read by the reflection pass along the
//! ray's direction.
//!
//! Faces and texel directions follow WebGPU's (and Vulkan's) cube map convention, so the
//! GPU samples the texels this module computes: face order +x, −x, +y, −y, +z, −z; on
//! each face the coordinates (s, t) ∈ [0, 1]² from [`cube_face`].

use glam::Vec3;

/// The radiance (linear rgb) arriving at `center` from every direction, `size`×`size`
/// texels per face.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    pub center: [f32; 3],
    pub size: u32,
    /// Face-major, then row (t) and column (s): texel (face, i, j) at
    /// `(face · size + j) · size + i`.
    pub texels: Vec<[f32; 3]>,
}

impl EnvironmentMap {
    /// The direction through face coordinates (s, t) of `face`.
    pub fn direction(face: usize, s: f32, t: f32) -> Vec3 {
        let (a, b) = (2.0 * s - 1.0, 2.0 * t - 1.0);
        // the inverse of `cube_face`'s (sc, tc) per face
        let d = match face {
            0 => Vec3::new(1.0, -b, -a),
            1 => Vec3::new(-1.0, -b, a),
            2 => Vec3::new(a, 1.0, b),
            3 => Vec3::new(a, -1.0, -b),
            4 => Vec3::new(a, -b, 1.0),
            _ => Vec3::new(-a, -b, -1.0),
        };
        d.normalize()
    }

    /// The direction through the centre of texel (i, j) of `face`.
    pub fn texel_direction(&self, face: usize, i: u32, j: u32) -> Vec3 {
        let n = self.size as f32;
        Self::direction(face, (i as f32 + 0.5) / n, (j as f32 + 0.5) / n)
    }

    /// The texel that direction `d` falls in (nearest; the GPU filters bilinearly).
    pub fn lookup(&self, d: Vec3) -> [f32; 3] {
        let (face, s, t) = cube_face(d);
        let n = self.size;
        let at = |c: f32| ((c * n as f32) as u32).min(n - 1);
        self.texels[((face as u32 * n + at(t)) * n + at(s)) as usize]
    }
}

/// The face of direction `d` and the coordinates (s, t) ∈ [0, 1]² on it: the major axis,
/// then WebGPU's and Vulkan's (sc, tc) per face.
pub fn cube_face(d: Vec3) -> (usize, f32, f32) {
    let m = d.abs();
    let (face, ma, sc, tc) = if m.x >= m.y && m.x >= m.z {
        if d.x > 0.0 {
            (0, m.x, -d.z, -d.y)
        } else {
            (1, m.x, d.z, -d.y)
        }
    } else if m.y >= m.z {
        if d.y > 0.0 {
            (2, m.y, d.x, d.z)
        } else {
            (3, m.y, d.x, -d.z)
        }
    } else if d.z > 0.0 {
        (4, m.z, d.x, -d.y)
    } else {
        (5, m.z, -d.x, -d.y)
    };
    (face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `direction` inverts `cube_face` on every face, and a texel's direction looks up that
    /// texel.
    #[test]
    fn texel_directions_round_trip_through_the_face_selection() {
        for face in 0..6 {
            for &(s, t) in &[(0.1f32, 0.2f32), (0.5, 0.5), (0.9, 0.35), (0.3, 0.8)] {
                let (f, s2, t2) = cube_face(EnvironmentMap::direction(face, s, t));
                assert_eq!(f, face);
                assert!(
                    (s - s2).abs() < 1e-5 && (t - t2).abs() < 1e-5,
                    "{face}: {s},{t} -> {s2},{t2}"
                );
            }
        }
        let n = 4;
        let env = EnvironmentMap {
            center: [0.0; 3],
            size: n,
            texels: (0..6 * n * n).map(|k| [k as f32, 0.0, 0.0]).collect(),
        };
        for face in 0..6 {
            for j in 0..n {
                for i in 0..n {
                    let k = (face as u32 * n + j) * n + i;
                    assert_eq!(env.lookup(env.texel_direction(face, i, j))[0], k as f32);
                }
            }
        }
    }
}
