//! What a ray learns where it hits a surface.

use crate::math::{Point3, Vec3};
use crate::ray::Ray;
use crate::texture::TexCoords;

/// The nearest intersection of a ray with the scene.
#[derive(Clone, Copy, Debug)]
pub struct HitRecord {
    /// The hit point p(t).
    pub point: Point3,
    /// Unit geometric normal, turned to face against the incoming ray: it
    /// decides the side a ray leaves to and where it starts.
    pub normal: Vec3,
    /// Unit shading normal on the same side as `normal`: interpolated from
    /// a mesh's vertex normals (smooth shading), else `normal` itself.
    /// Materials scatter around it.
    pub shading_normal: Vec3,
    /// Surface coordinates: a quad's (α, β), a triangle's interpolated
    /// texture coordinates or barycentrics (b₁, b₂); (0, 0) on spheres, whose
    /// (φ/2π, θ/π) [`Sphere::uv`](crate::geometry::Sphere::uv) computes from
    /// the outward normal when a texture needs them.
    pub uv: [f32; 2],
    /// The ray parameter of the hit.
    pub t: f32,
    /// True when the ray hits the outside of the surface (it travels against
    /// the outward normal); false when it comes from inside.
    pub front_face: bool,
    /// Index of the hit object's material in the scene's material table.
    pub material: u32,
    /// Index of the hit primitive in the scene's tree.
    pub object: u32,
    /// The second set of texture coordinates (a mesh's `TEXCOORD_1`; `uv`
    /// elsewhere).
    pub uv1: [f32; 2],
    /// ∂p/∂u: the surface's tangent along its first texture coordinate
    /// (not unit; zero where it has none, as at a sphere's poles), which
    /// anisotropic materials align with. Where a mesh gives tangents, its
    /// tangent, at the length of ∂p/∂u.
    pub dpdu: Vec3,
    /// ∂p/∂v, along the second coordinate (v up the image); where a mesh
    /// gives tangents, its bitangent at the length of ∂p/∂v. With `dpdu`,
    /// the tangent space of normal and bump maps.
    pub dpdv: Vec3,
    /// The mesh's vertex colour and alpha there (glTF `COLOR_0`); white
    /// and opaque elsewhere.
    pub color: glam::Vec4,
    /// A bound on how far `point` may lie from the true surface through
    /// `f32` rounding. 0 when the scene's epsilon is 0, so that rays leave
    /// from the point itself (the notes' shadow acne).
    pub error: f32,
}

impl HitRecord {
    /// Where textures are looked up at this hit.
    #[inline(always)]
    pub fn tex_coords(&self) -> TexCoords {
        TexCoords {
            uv: self.uv,
            uv1: self.uv1,
            point: self.point,
        }
    }

    /// Where a ray leaving the surface along `direction` starts: the hit
    /// point moved off the surface, to the side `direction` goes, by the
    /// rounding bound `error`. Started at the rounded point itself, a ray
    /// could find the surface it leaves again a little way off: on the
    /// radius-1000 ground of the cover the rounding (≈ 3·10⁻⁵) made 2.5% of
    /// bounces hit the ground again, beyond any small epsilon.
    #[inline(always)]
    pub fn spawn_origin(&self, direction: Vec3) -> Point3 {
        let offset = if direction.dot(self.normal) >= 0.0 {
            self.error
        } else {
            -self.error
        };
        self.point + offset * self.normal
    }

    /// Whether the shading normal differs from the geometric one (an
    /// interpolated vertex normal).
    #[inline(always)]
    pub fn is_smooth(&self) -> bool {
        self.shading_normal != self.normal
    }

    /// The unit geometric normal pointing out of the surface (away from its
    /// inside, whichever side the ray came from).
    #[inline(always)]
    pub fn outward_normal(&self) -> Vec3 {
        if self.front_face {
            self.normal
        } else {
            -self.normal
        }
    }
}

/// Orients an outward normal against the ray and records which side was hit.
///
/// The sign of `direction · outward_normal` tells the side: negative means the
/// ray and the normal point in opposite directions, so the ray arrives from
/// outside.
#[inline]
pub fn face_normal(ray: &Ray, outward_normal: Vec3) -> (Vec3, bool) {
    let front_face = ray.direction.dot(outward_normal) < 0.0;
    let normal = if front_face {
        outward_normal
    } else {
        -outward_normal
    };
    (normal, front_face)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Sphere;
    use crate::math::Interval;

    #[test]
    fn ray_from_outside_hits_the_front_face_with_the_outward_normal() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        let (n, front) = face_normal(&ray, Vec3::Z);
        assert!(front);
        assert_eq!(n, Vec3::Z);
    }

    #[test]
    fn ray_from_inside_hits_the_back_face_with_the_normal_flipped() {
        let sphere = Sphere::new(Vec3::ZERO, 2.0);
        let ray = Ray::new(Vec3::new(0.5, 0.0, 0.0), Vec3::X);
        let t = sphere.hit(&ray, Interval::new(0.0, f32::INFINITY)).unwrap();
        assert_eq!(t, 1.5);
        let outward = sphere.outward_normal(ray.at(t));
        assert_eq!(outward, Vec3::X);
        let (n, front) = face_normal(&ray, outward);
        assert!(!front);
        assert_eq!(n, -Vec3::X, "the normal faces against the ray");
        assert!(n.dot(ray.direction) < 0.0);
    }

    #[test]
    fn the_normal_always_opposes_the_ray() {
        for d in [Vec3::new(1.0, 2.0, -3.0), Vec3::new(-1.0, 0.5, 0.2)] {
            for outward in [Vec3::Y, -Vec3::Y, Vec3::new(0.6, 0.8, 0.0)] {
                let (n, front) = face_normal(&Ray::new(Vec3::ZERO, d), outward);
                assert!(n.dot(d) <= 0.0);
                assert_eq!(front, d.dot(outward) < 0.0);
                assert_eq!(n, if front { outward } else { -outward });
            }
        }
    }
}
