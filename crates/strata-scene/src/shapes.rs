//! Geometry helpers for procedural scenes: a [`MeshBuilder`] that emits
//! counter-clockwise (outward-facing) triangles with flat normals on planar
//! faces and smooth normals on curved ones.
//!
//! Conventions: right-handed, +Y up, units are metres in the built-in scenes.
//! A face is front-facing when its vertices appear counter-clockwise seen from
//! the side its normal points to (the [`Mesh`] convention).

use glam::{Mat4, Vec3};

use crate::model::Mesh;
use crate::normals::{face_normal, normalize_or_fallback, FALLBACK_NORMAL};

/// Accumulates vertices and triangles; [`MeshBuilder::build`] turns them into a [`Mesh`].
#[derive(Clone, Debug, Default)]
pub struct MeshBuilder {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
}

impl MeshBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of triangles so far.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// `true` when no triangle has been added.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Adds one vertex (the normal is normalised, +Y when degenerate) and returns its index.
    pub fn vertex(&mut self, p: Vec3, n: Vec3, uv: [f32; 2]) -> u32 {
        let i = self.positions.len() as u32;
        self.positions.push(p.to_array());
        self.normals.push(normalize_or_fallback(n).to_array());
        self.uvs.push(uv);
        i
    }

    /// Adds a triangle of existing vertex indices (counter-clockwise = front).
    pub fn index_triangle(&mut self, a: u32, b: u32, c: u32) {
        self.indices.extend_from_slice(&[a, b, c]);
    }

    /// Adds a flat-shaded triangle (counter-clockwise = front).
    pub fn triangle(&mut self, a: Vec3, b: Vec3, c: Vec3) {
        let n = face_normal(a, b, c).unwrap_or(Vec3::from(FALLBACK_NORMAL));
        let i = self.vertex(a, n, [0.0, 0.0]);
        self.vertex(b, n, [1.0, 0.0]);
        self.vertex(c, n, [0.0, 1.0]);
        self.index_triangle(i, i + 1, i + 2);
    }

    /// Adds a flat-shaded planar quad `p[0..4]`, counter-clockwise seen from its front.
    /// UVs are (0,0), (1,0), (1,1), (0,1) at the four corners.
    pub fn quad(&mut self, p: [Vec3; 4]) {
        let n = face_normal(p[0], p[1], p[2])
            .or_else(|| face_normal(p[0], p[2], p[3]))
            .unwrap_or(Vec3::from(FALLBACK_NORMAL));
        let uv = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let i = self.positions.len() as u32;
        for k in 0..4 {
            self.vertex(p[k], n, uv[k]);
        }
        self.index_triangle(i, i + 1, i + 2);
        self.index_triangle(i, i + 2, i + 3);
    }

    /// Adds the quad `p` (in either winding) so that its front faces along `toward`.
    pub fn quad_facing(&mut self, p: [Vec3; 4], toward: Vec3) {
        let n = (p[1] - p[0]).cross(p[2] - p[0]) + (p[2] - p[0]).cross(p[3] - p[0]);
        if n.dot(toward) >= 0.0 {
            self.quad(p);
        } else {
            self.quad([p[0], p[3], p[2], p[1]]);
        }
    }

    /// Adds a rectangle with centre `c` and half-edge vectors `half_u`, `half_v`;
    /// its front normal is `normalize(half_u × half_v)` (as for [`crate::Light::Rect`]).
    pub fn rect(&mut self, c: Vec3, half_u: Vec3, half_v: Vec3) {
        self.quad([
            c - half_u - half_v,
            c + half_u - half_v,
            c + half_u + half_v,
            c - half_u + half_v,
        ]);
    }

    /// Adds an axis-aligned box with outward faces (12 triangles, flat normals).
    pub fn cuboid(&mut self, min: Vec3, max: Vec3) {
        let c = 0.5 * (min + max);
        let h = 0.5 * (max - min);
        self.oriented_box(c, [Vec3::X * h.x, Vec3::Y * h.y, Vec3::Z * h.z]);
    }

    /// Adds a box with centre `c` and three mutually perpendicular half-axis
    /// vectors, with outward faces.
    pub fn oriented_box(&mut self, c: Vec3, half_axes: [Vec3; 3]) {
        for k in 0..3 {
            let a = half_axes[k];
            let b = half_axes[(k + 1) % 3];
            let d = half_axes[(k + 2) % 3];
            for s in [1.0f32, -1.0] {
                let fc = c + s * a;
                let corners = [fc - b - d, fc + b - d, fc + b + d, fc - b + d];
                self.quad_facing(corners, s * a);
            }
        }
    }

    /// Adds a closed hexahedron from its bottom and top quads (corresponding
    /// corners, each quad in order around its boundary, planar faces assumed),
    /// with every face oriented away from the centroid.
    pub fn hexahedron(&mut self, bottom: [Vec3; 4], top: [Vec3; 4]) {
        let centroid = (bottom.iter().sum::<Vec3>() + top.iter().sum::<Vec3>()) / 8.0;
        let mut face = |q: [Vec3; 4]| {
            let fc = q.iter().sum::<Vec3>() / 4.0;
            self.quad_facing(q, fc - centroid);
        };
        face(bottom);
        face(top);
        for i in 0..4 {
            let j = (i + 1) % 4;
            face([bottom[i], bottom[j], top[j], top[i]]);
        }
    }

    /// Adds a vertical cylinder (axis +Y) standing on `base` (centre of the
    /// bottom cap), with `segments` side quads and smooth side normals; flat
    /// caps when `caps` is true.
    pub fn cylinder(&mut self, base: Vec3, radius: f32, height: f32, segments: u32, caps: bool) {
        let segments = segments.max(3);
        let dir = |i: u32| {
            let a = std::f32::consts::TAU * i as f32 / segments as f32;
            Vec3::new(a.cos(), 0.0, -a.sin())
        };
        // Side: one ring of vertex pairs (seam duplicated for the UVs).
        let first = self.positions.len() as u32;
        for i in 0..=segments {
            let d = dir(i);
            let u = i as f32 / segments as f32;
            self.vertex(base + d * radius, d, [u, 1.0]);
            self.vertex(base + d * radius + Vec3::Y * height, d, [u, 0.0]);
        }
        for i in 0..segments {
            let (b0, t0, b1, t1) = (first + 2 * i, first + 2 * i + 1, first + 2 * i + 2, first + 2 * i + 3);
            // dir(i) → dir(i+1) turns counter-clockwise seen from above (+Y), so
            // (b0, b1, t1) is counter-clockwise seen from outside.
            self.index_triangle(b0, b1, t1);
            self.index_triangle(b0, t1, t0);
        }
        if caps {
            for (y, n) in [(height, Vec3::Y), (0.0, -Vec3::Y)] {
                let c = self.vertex(base + Vec3::Y * y, n, [0.5, 0.5]);
                let ring = self.positions.len() as u32;
                for i in 0..segments {
                    let d = dir(i);
                    self.vertex(base + d * radius + Vec3::Y * y, n, [0.5 + 0.5 * d.x, 0.5 + 0.5 * d.z]);
                }
                for i in 0..segments {
                    let (a, b) = (ring + i, ring + (i + 1) % segments);
                    if n.y > 0.0 {
                        self.index_triangle(c, a, b);
                    } else {
                        self.index_triangle(c, b, a);
                    }
                }
            }
        }
    }

    /// Adds a UV sphere of radius `radius` around `c` with smooth outward
    /// normals: `rings` ≥ 2 latitude bands (triangle fans at the poles) and
    /// `segments` ≥ 3 longitude slices, `2 · segments · (rings − 1)` triangles.
    pub fn sphere(&mut self, c: Vec3, radius: f32, segments: u32, rings: u32) {
        let (segments, rings) = (segments.max(3), rings.max(2));
        let point = |i: u32, j: u32| {
            let theta = std::f32::consts::PI * j as f32 / rings as f32; // from +Y
            let phi = std::f32::consts::TAU * i as f32 / segments as f32;
            Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin())
        };
        let first = self.positions.len() as u32;
        // Rows j = 0..=rings of segments + 1 vertices (seam duplicated for the UVs).
        for j in 0..=rings {
            for i in 0..=segments {
                let d = point(i, j);
                self.vertex(c + d * radius, d, [i as f32 / segments as f32, j as f32 / rings as f32]);
            }
        }
        let at = |i: u32, j: u32| first + j * (segments + 1) + i;
        for j in 0..rings {
            for i in 0..segments {
                // phi grows counter-clockwise seen from +Y, theta downwards:
                // (j, i) → (j + 1, i) → (j + 1, i + 1) is counter-clockwise from outside.
                if j > 0 {
                    self.index_triangle(at(i, j), at(i, j + 1), at(i + 1, j));
                }
                if j + 1 < rings {
                    self.index_triangle(at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
                }
            }
        }
    }

    /// Adds an arcade panel: the solid spandrel around a semicircular arch
    /// opening, in the XY plane and extruded along Z from `z0` to `z1`.
    ///
    /// The opening is the half-disc of radius `half_span` centred at
    /// (`center_x`, `spring_y`); the panel fills the rest of the rectangle
    /// x ∈ [center_x − half_span, center_x + half_span], y ∈ [spring_y, top_y]
    /// (`top_y − spring_y ≥ half_span`). Emits the front and back faces, the
    /// smooth intrados (the arch's underside, facing the opening) and the top
    /// face; the two vertical sides are left open (they abut the neighbouring
    /// panels in an arcade).
    #[allow(clippy::too_many_arguments)]
    pub fn arch_panel(
        &mut self,
        center_x: f32,
        spring_y: f32,
        half_span: f32,
        top_y: f32,
        z0: f32,
        z1: f32,
        segments: u32,
    ) {
        let r = half_span;
        let h = (top_y - spring_y).max(r);
        let (z0, z1) = (z0.min(z1), z0.max(z1));
        // Angles from 0 to π, including the two corner directions of the rectangle.
        let segments = segments.max(2);
        let corner = h.atan2(r);
        let mut angles: Vec<f32> = (0..=segments)
            .map(|i| std::f32::consts::PI * i as f32 / segments as f32)
            .collect();
        angles.extend([corner, std::f32::consts::PI - corner]);
        angles.sort_by(f32::total_cmp);
        angles.dedup_by(|a, b| (*a - *b).abs() < 1e-5);
        let c = Vec3::new(center_x, spring_y, 0.0);
        let inner = |a: f32| c + Vec3::new(a.cos(), a.sin(), 0.0) * r;
        let outer = |a: f32| {
            let d = Vec3::new(a.cos(), a.sin(), 0.0);
            let tx = if d.x.abs() > 1e-6 { r / d.x.abs() } else { f32::INFINITY };
            let ty = if d.y > 1e-6 { h / d.y } else { f32::INFINITY };
            c + d * tx.min(ty)
        };
        let zf = |p: Vec3, z: f32| Vec3::new(p.x, p.y, z);
        for w in angles.windows(2) {
            let (a0, a1) = (w[0], w[1]);
            let (i0, i1, o0, o1) = (inner(a0), inner(a1), outer(a0), outer(a1));
            // Front (+Z) and back (−Z) faces of the spandrel. The outer points
            // may coincide with the inner ones at the springs: drop degenerate halves.
            for (z, facing) in [(z1, Vec3::Z), (z0, -Vec3::Z)] {
                let q = [zf(i0, z), zf(i1, z), zf(o1, z), zf(o0, z)];
                if (o0 - i0).length() < 1e-6 {
                    self.triangle_facing([q[0], q[1], q[2]], facing);
                } else if (o1 - i1).length() < 1e-6 {
                    self.triangle_facing([q[0], q[1], q[3]], facing);
                } else {
                    self.quad_facing(q, facing);
                }
            }
            // Intrados: smooth normals pointing at the arch centre.
            let (n0, n1) = (c - i0, c - i1);
            let base = self.positions.len() as u32;
            self.vertex(zf(i0, z0), n0, [a0, 0.0]);
            self.vertex(zf(i1, z0), n1, [a1, 0.0]);
            self.vertex(zf(i1, z1), n1, [a1, 1.0]);
            self.vertex(zf(i0, z1), n0, [a0, 1.0]);
            // Seen from the centre (inside the opening) i0 → i1 runs counter-clockwise
            // in XY, i.e. clockwise seen from below; orient explicitly.
            let fc = 0.5 * (i0 + i1);
            let geo = (zf(i1, z0) - zf(i0, z0)).cross(zf(i1, z1) - zf(i0, z0));
            if geo.dot(c - fc) >= 0.0 {
                self.index_triangle(base, base + 1, base + 2);
                self.index_triangle(base, base + 2, base + 3);
            } else {
                self.index_triangle(base, base + 2, base + 1);
                self.index_triangle(base, base + 3, base + 2);
            }
        }
        // Top face.
        let (x0, x1) = (center_x - r, center_x + r);
        let y = spring_y + h;
        self.quad_facing(
            [
                Vec3::new(x0, y, z0),
                Vec3::new(x1, y, z0),
                Vec3::new(x1, y, z1),
                Vec3::new(x0, y, z1),
            ],
            Vec3::Y,
        );
    }

    /// Adds the triangle `p` (in either winding) so that its front faces along `toward`.
    pub fn triangle_facing(&mut self, p: [Vec3; 3], toward: Vec3) {
        if (p[1] - p[0]).cross(p[2] - p[0]).dot(toward) >= 0.0 {
            self.triangle(p[0], p[1], p[2]);
        } else {
            self.triangle(p[0], p[2], p[1]);
        }
    }

    /// Appends `other` transformed by `xf` (normals by its inverse transpose;
    /// winding is flipped when `xf` mirrors).
    pub fn append(&mut self, other: &MeshBuilder, xf: Mat4) {
        let nxf = glam::Mat3::from_mat4(xf).inverse().transpose();
        let flip = xf.determinant() < 0.0;
        let base = self.positions.len() as u32;
        for i in 0..other.positions.len() {
            self.positions
                .push(xf.transform_point3(Vec3::from(other.positions[i])).to_array());
            self.normals
                .push(normalize_or_fallback(nxf * Vec3::from(other.normals[i])).to_array());
            self.uvs.push(other.uvs[i]);
        }
        for t in other.indices.chunks_exact(3) {
            if flip {
                self.index_triangle(base + t[0], base + t[2], base + t[1]);
            } else {
                self.index_triangle(base + t[0], base + t[1], base + t[2]);
            }
        }
    }

    /// Finishes the mesh with the given name and material index.
    pub fn build(self, name: &str, material: usize) -> Mesh {
        Mesh {
            name: name.into(),
            positions: self.positions,
            normals: self.normals,
            uvs: self.uvs,
            indices: self.indices,
            material,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Signed volume of a closed mesh (positive when faces point outwards).
    fn signed_volume(m: &MeshBuilder) -> f32 {
        m.indices
            .chunks_exact(3)
            .map(|t| {
                let p = |i: u32| Vec3::from(m.positions[i as usize]);
                p(t[0]).dot(p(t[1]).cross(p(t[2]))) / 6.0
            })
            .sum()
    }

    /// Every triangle's geometric normal agrees with its vertex normals.
    fn normals_agree_with_winding(m: &MeshBuilder) {
        for t in m.indices.chunks_exact(3) {
            let p = |i: u32| Vec3::from(m.positions[i as usize]);
            let g = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
            if g.length() < 1e-9 {
                continue;
            }
            for &i in t {
                assert!(
                    g.dot(Vec3::from(m.normals[i as usize])) > 0.0,
                    "triangle {t:?} winding vs normal"
                );
            }
        }
    }

    #[test]
    fn box_is_outward() {
        let mut m = MeshBuilder::new();
        m.cuboid(Vec3::new(1.0, 2.0, 3.0), Vec3::new(2.0, 4.0, 6.0));
        assert_eq!(m.triangle_count(), 12);
        assert!((signed_volume(&m) - 6.0).abs() < 1e-4);
        normals_agree_with_winding(&m);
    }

    #[test]
    fn cylinder_is_outward() {
        let mut m = MeshBuilder::new();
        m.cylinder(Vec3::new(1.0, 0.0, -2.0), 0.5, 3.0, 64, true);
        let v = std::f32::consts::PI * 0.25 * 3.0;
        assert!((signed_volume(&m) - v).abs() < 0.01 * v, "{}", signed_volume(&m));
        normals_agree_with_winding(&m);
    }

    #[test]
    fn sphere_is_outward_and_closed() {
        let mut m = MeshBuilder::new();
        m.sphere(Vec3::new(1.0, 2.0, 3.0), 0.5, 32, 16);
        assert_eq!(m.triangle_count(), 2 * 32 * 15);
        let v = 4.0 / 3.0 * std::f32::consts::PI * 0.125;
        // Signed volume is translation-invariant only for closed meshes.
        assert!((signed_volume(&m) - v).abs() < 0.03 * v, "{}", signed_volume(&m));
        normals_agree_with_winding(&m);
    }

    #[test]
    fn hexahedron_is_outward() {
        let b = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let t = b.map(|p| p + Vec3::Y * 2.0);
        let mut m = MeshBuilder::new();
        m.hexahedron(b, t);
        assert!((signed_volume(&m) - 2.0).abs() < 1e-4);
        normals_agree_with_winding(&m);
    }

    #[test]
    fn arch_panel_faces_agree() {
        let mut m = MeshBuilder::new();
        m.arch_panel(0.0, 4.0, 1.5, 6.0, -0.4, 0.4, 16);
        normals_agree_with_winding(&m);
        // The intrados normals point at the arch centre (below the crown, at the centre line).
        let crown = m
            .positions
            .iter()
            .zip(&m.normals)
            .filter(|(p, _)| p[0].abs() < 1e-4 && (p[1] - 5.5).abs() < 1e-4)
            .map(|(_, n)| Vec3::from(*n))
            .find(|n| n.y < -0.9);
        assert!(crown.is_some());
    }
}
