//! Vertex-normal generation and repair.
//!
//! - [`smooth_normals`]: area-weighted smooth vertex normals (the sum of the
//!   un-normalised face normals `(b − a) × (c − a)` of the triangles around each
//!   vertex, so larger triangles count more), used for meshes without normals
//!   such as the Stanford bunny and dragon;
//! - [`ensure_normals`]: fills in or repairs a mesh's normals in place;
//! - [`flat_shaded`]: a copy of a mesh with unshared vertices and per-face normals.
//!
//! Degenerate input never yields NaN: a vertex whose accumulated normal has
//! (near) zero length, or is not finite, gets [`FALLBACK_NORMAL`] (+Y).

use glam::Vec3;

use crate::model::Mesh;

/// Normal used where none can be computed (degenerate or isolated vertices).
pub const FALLBACK_NORMAL: [f32; 3] = [0.0, 1.0, 0.0];

/// Un-normalised face normal `(b − a) × (c − a)`; its length is twice the
/// triangle's area and it points to the side from which `a, b, c` appear
/// counter-clockwise.
pub fn face_normal_weighted(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    (b - a).cross(c - a)
}

/// Unit face normal of a counter-clockwise triangle, or `None` when the
/// triangle is degenerate (zero area or non-finite coordinates).
pub fn face_normal(a: Vec3, b: Vec3, c: Vec3) -> Option<Vec3> {
    let n = face_normal_weighted(a, b, c);
    let len = n.length();
    (len.is_finite() && len > 0.0)
        .then(|| n / len)
        .filter(|n| n.is_finite())
}

/// Normalises `n`, falling back to +Y when it is zero-length or not finite.
pub fn normalize_or_fallback(n: Vec3) -> Vec3 {
    let len = n.length();
    if len.is_finite() && len > 1e-30 {
        let u = n / len;
        if u.is_finite() {
            return u;
        }
    }
    Vec3::from(FALLBACK_NORMAL)
}

/// Area-weighted smooth vertex normals of an indexed triangle list.
///
/// Returns one unit normal per position. Triangles with an index out of range
/// or non-finite corners are ignored; vertices that end up with no usable
/// contribution get +Y. Never returns NaN.
pub fn smooth_normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let (i0, i1, i2) = (t[0] as usize, t[1] as usize, t[2] as usize);
        let (Some(a), Some(b), Some(c)) = (positions.get(i0), positions.get(i1), positions.get(i2)) else {
            continue;
        };
        let n = face_normal_weighted(Vec3::from(*a), Vec3::from(*b), Vec3::from(*c));
        if !n.is_finite() {
            continue;
        }
        acc[i0] += n;
        acc[i1] += n;
        acc[i2] += n;
    }
    acc.into_iter().map(|n| normalize_or_fallback(n).to_array()).collect()
}

/// Makes `mesh.normals` usable: generates smooth normals when the mesh has
/// none (or a count that does not match `positions`), otherwise re-normalises
/// the given ones; a given normal that is zero-length (or not finite) is
/// replaced by the generated smooth normal of its vertex (+Y where that too is
/// degenerate).
///
/// Returns `true` when all the normals were generated.
pub fn ensure_normals(mesh: &mut Mesh) -> bool {
    if mesh.normals.len() != mesh.positions.len() {
        mesh.normals = smooth_normals(&mesh.positions, &mesh.indices);
        return true;
    }
    let usable = |n: Vec3| {
        let len = n.length();
        len.is_finite() && len > 1e-30 && (n / len).is_finite()
    };
    let mut smooth: Option<Vec<[f32; 3]>> = None;
    for (i, n) in mesh.normals.iter_mut().enumerate() {
        let v = Vec3::from(*n);
        *n = if usable(v) {
            normalize_or_fallback(v).to_array()
        } else {
            smooth.get_or_insert_with(|| smooth_normals(&mesh.positions, &mesh.indices))[i]
        };
    }
    false
}

/// A copy of `mesh` with every triangle given its own three vertices and its
/// face normal (degenerate triangles get +Y), for faceted shading.
/// Out-of-range indices are skipped.
pub fn flat_shaded(mesh: &Mesh) -> Mesh {
    let mut out = Mesh {
        name: mesh.name.clone(),
        material: mesh.material,
        ..Default::default()
    };
    let has_uv = mesh.uvs.len() == mesh.positions.len();
    for t in mesh.indices.chunks_exact(3) {
        let idx = [t[0] as usize, t[1] as usize, t[2] as usize];
        if idx.iter().any(|&i| i >= mesh.positions.len()) {
            continue;
        }
        let p = idx.map(|i| Vec3::from(mesh.positions[i]));
        let n = face_normal(p[0], p[1], p[2])
            .unwrap_or(Vec3::from(FALLBACK_NORMAL))
            .to_array();
        for (k, &i) in idx.iter().enumerate() {
            out.indices.push(out.positions.len() as u32);
            out.positions.push(p[k].to_array());
            out.normals.push(n);
            out.uvs.push(if has_uv { mesh.uvs[i] } else { [0.0; 2] });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_weighting_prefers_large_triangles() {
        // Two triangles sharing vertex 0: a big one in the XZ plane (normal +Y)
        // and a small one in the XY plane (normal +Z).
        let positions = [
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 10.0],
            [10.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let n = smooth_normals(&positions, &[0, 1, 2, 0, 3, 4]);
        let n0 = Vec3::from(n[0]);
        assert!((n0.length() - 1.0).abs() < 1e-6);
        assert!(n0.y > 0.99 && n0.z > 0.0, "{n0}");
    }

    #[test]
    fn degenerate_gives_fallback() {
        let positions = [[1.0, 2.0, 3.0]; 3];
        let n = smooth_normals(&positions, &[0, 1, 2]);
        assert_eq!(n, vec![FALLBACK_NORMAL; 3]);
        let isolated = smooth_normals(&[[0.0; 3]], &[]);
        assert_eq!(isolated, vec![FALLBACK_NORMAL]);
    }
}
