//! Affine transforms that place objects and mesh instances in a scene.
//!
//! A transform is written as a list of [`TransformStep`]s. The steps are
//! applied to the object **in the order written, the first entry first**, so
//! for steps M₁, M₂, …, Mₙ the object-to-world matrix is Mₙ⋯M₂M₁ (column
//! vectors, p_world = M p_object). Translating by (1, 0, 0) and then rotating
//! 90° about z takes the object's point (1, 0, 0) to (2, 0, 0) and then to
//! (0, 2, 0); written the other way round, the rotation comes first and the
//! same point ends at (1, 1, 0):
//!
//! ```
//! use lumen::geometry::transform::{Transform, TransformStep};
//! use lumen::math::Vec3;
//!
//! let translate = TransformStep::Translate([1.0, 0.0, 0.0]);
//! let rotate = TransformStep::Rotate { axis: [0.0, 0.0, 1.0], degrees: 90.0 };
//!
//! let t = Transform::from_steps(&[translate, rotate]).unwrap();
//! assert!((t.point(Vec3::X) - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-6);
//!
//! let r = Transform::from_steps(&[rotate, translate]).unwrap();
//! assert!((r.point(Vec3::X) - Vec3::new(1.0, 1.0, 0.0)).length() < 1e-6);
//! ```
//!
//! Matrices are composed and inverted in `f64` (glam's [`DAffine3`]) and only
//! then rounded to the `f32` copies used while rendering, so that a long list
//! of steps does not accumulate `f32` rounding. Lists that would not survive
//! that rounding (values beyond the range of `f32`, singular or nearly singular
//! matrices, see [`MAX_CONDITION`]) are refused with a [`TransformError`]
//! naming the step.
//!
//! Intersection kernels work in object space: [`Transform::to_object_ray`]
//! gives the ray there, with the unit-length direction the kernels require and
//! the factor that turns object-space distances back into world distances.

use std::fmt;

use glam::{Affine3A, DAffine3, DMat3, DMat4, DVec3, Mat3A};
use thiserror::Error;

use crate::geometry::bvh_build::Aabb;
use crate::math::{Point3, Vec3};
use crate::ray::Ray;

/// The largest accepted condition number κ = ‖A‖_F·‖A⁻¹‖_F of a transform's
/// linear part A (Frobenius norms): 2²⁰ ≈ 1.05·10⁶.
///
/// Why this bound: rendering uses `f32` copies of A and A⁻¹. Rounding A to
/// `f32` changes it by E with ‖E‖_F ≤ u‖A‖_F, u = 2⁻²⁴. The nearest singular
/// matrix lies at distance σ_min(A) = 1/‖A⁻¹‖₂ ≥ 1/‖A⁻¹‖_F = ‖A‖_F/κ, so when
/// κu ≥ 1 the rounding alone may make the stored matrix singular, and its
/// inverse means nothing. Below that, the inverse of the stored matrix is off
/// from A⁻¹ by a relative error of at most κu/(1 − κu) (standard perturbation
/// bound), that is about log₂κ of the 24 bits of a coordinate are lost in the
/// worst direction on every world ↔ object mapping. The limit κ ≤ 2²⁰ keeps
/// the rounding below 1/16 of the distance to singularity (relative error of
/// the inverse ≤ 1/15) while still admitting strongly flattened objects: an
/// axis scale of 1 : 10⁻⁵ (κ ≈ 1.4·10⁵) is accepted, 1 : 10⁻⁶ (κ ≈ 1.4·10⁶)
/// is refused.
///
/// The condition number is used rather than the determinant relative to the
/// matrix's size, |det A|/‖A‖³, because the latter misjudges both ways: the
/// well-conditioned uniform scale by 10⁻³⁰ has det 10⁻⁹⁰, and diag(1, 10³, 10⁻³)
/// has det 1 but κ ≈ 10⁶.
pub const MAX_CONDITION: f64 = (1u32 << 20) as f64;

/// One step of a transform, as written in a scene file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransformStep {
    /// Move by the vector (x, y, z).
    Translate([f64; 3]),
    /// Rotate about `axis` (through the origin; any non-zero length, it is
    /// normalised) by `degrees`, right-handed: counter-clockwise when looking
    /// down the axis towards the origin, so 90° about +y takes +x to −z.
    Rotate {
        /// The axis direction.
        axis: [f64; 3],
        /// The angle in degrees.
        degrees: f64,
    },
    /// Scale each axis by its factor (non-zero; negative factors mirror). A
    /// uniform scale by s is `[s, s, s]`.
    Scale([f64; 3]),
    /// A general affine matrix, row-major as written in a scene file:
    /// `rows[i][j]` is row i, column j, and the translation is column 3. The
    /// last row must be exactly `[0, 0, 0, 1]` (projective matrices are
    /// refused).
    Matrix([[f64; 4]; 4]),
}

/// Why a list of transform steps was refused.
///
/// Displays as `transform[INDEX]: message`; a scene loader prefixes the path
/// of the object, giving e.g. `objects[3].transform[1]: …`.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[error("transform[{index}]: {message}")]
pub struct TransformError {
    /// Index of the refused step in the list.
    pub index: usize,
    /// What is wrong with it.
    pub message: String,
}

/// An invertible affine transform from object space to world space, with its
/// inverse.
///
/// Both directions are kept in `f64` (for composing and inverting exactly
/// enough) and in `f32` (for rendering), together with the matrix that maps
/// normals: the inverse transpose of the linear part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    to_world64: DAffine3,
    to_object64: DAffine3,
    to_world: Affine3A,
    to_object: Affine3A,
    /// (A⁻¹)ᵀ for the linear part A of `to_world`.
    normal_matrix: Mat3A,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The transform that leaves everything in place.
    pub const IDENTITY: Transform = Transform {
        to_world64: DAffine3::IDENTITY,
        to_object64: DAffine3::IDENTITY,
        to_world: Affine3A::IDENTITY,
        to_object: Affine3A::IDENTITY,
        normal_matrix: Mat3A::IDENTITY,
    };

    /// The transform of `steps`, applied to the object in the order written
    /// (the first entry first): the matrix is Mₙ⋯M₂M₁. An empty list is the
    /// identity.
    ///
    /// Refused, with the index of the offending step: values that are not
    /// finite or lie beyond the range of `f32`; a zero-length rotation axis; a
    /// scale component that is zero or too small for `f32`; a matrix whose last
    /// row is not `[0, 0, 0, 1]`; a singular matrix; and any step after which
    /// the transform so far is nearly singular (condition number above
    /// [`MAX_CONDITION`]) or has a matrix or inverse beyond the range of `f32`.
    pub fn from_steps(steps: &[TransformStep]) -> Result<Transform, TransformError> {
        let mut product = DAffine3::IDENTITY;
        let mut result = Transform::IDENTITY;
        for (index, step) in steps.iter().enumerate() {
            let error = |message: String| TransformError { index, message };
            let m = step_matrix(step).map_err(error)?;
            // The step alone first, so that its own fault is named as such.
            let alone = Transform::from_affine(m).map_err(error)?;
            product = m * product;
            result = if index == 0 {
                alone
            } else {
                Transform::from_affine(product).map_err(|message| {
                    error(format!("together with the steps before it, {message}"))
                })?
            };
        }
        Ok(result)
    }

    /// The transform with object-to-world matrix `m`, after the checks of
    /// [`from_steps`](Self::from_steps) on the whole matrix.
    fn from_affine(m: DAffine3) -> Result<Transform, String> {
        if !fits_f32(&m) {
            return Err("the matrix has entries beyond the range of f32".into());
        }
        let det = m.matrix3.determinant();
        if det == 0.0 || !det.is_finite() {
            return Err("the matrix is singular (determinant 0): it has no inverse".into());
        }
        let inv = m.inverse();
        let condition = frobenius(&m.matrix3) * frobenius(&inv.matrix3);
        if !(condition <= MAX_CONDITION) {
            return Err(format!(
                "the matrix is nearly singular (determinant {det:e}, condition number \
                 {condition:.3e} above the limit 2^20 = {MAX_CONDITION:.3e}): its inverse \
                 is not reliable in f32"
            ));
        }
        if !fits_f32(&inv) {
            return Err("the inverse matrix has entries beyond the range of f32".into());
        }
        Ok(Transform::from_pair(m, inv))
    }

    /// Builds the `f32` copies of a checked pair of inverse matrices.
    fn from_pair(to_world64: DAffine3, to_object64: DAffine3) -> Transform {
        Transform {
            to_world64,
            to_object64,
            to_world: to_f32(&to_world64),
            to_object: to_f32(&to_object64),
            normal_matrix: mat3_to_f32(&to_object64.matrix3.transpose()),
        }
    }

    /// Whether this is exactly the identity (as for an empty list of steps, or
    /// steps that cancel exactly, such as a rotation by 360°).
    pub fn is_identity(&self) -> bool {
        self.to_world64 == DAffine3::IDENTITY
    }

    /// Whether it mirrors: turns a right-handed frame left-handed (and a
    /// triangle's winding over).
    pub fn mirrors(&self) -> bool {
        self.to_world64.matrix3.determinant() < 0.0
    }

    /// The transform that applies `self` first and then `next`: matrix
    /// `next · self`. `a.then(&b)` is the transform of the steps of `a`
    /// followed by those of `b`.
    ///
    /// `None` if the product fails the checks of
    /// [`from_steps`](Self::from_steps) (beyond the range of `f32`, or nearly
    /// singular).
    pub fn then(&self, next: &Transform) -> Option<Transform> {
        Transform::from_affine(next.to_world64 * self.to_world64).ok()
    }

    /// Function composition `self ∘ inner`: the transform that applies `inner`
    /// first and then `self`, matrix `self · inner`. The same as
    /// `inner.then(self)`; a mesh instance placed by `placement` inside a group
    /// placed by `group` is at `group.compose(&placement)`.
    ///
    /// `None` under the same conditions as [`then`](Self::then).
    pub fn compose(&self, inner: &Transform) -> Option<Transform> {
        inner.then(self)
    }

    /// The inverse transform, from world space to object space.
    pub fn inverse(&self) -> Transform {
        Transform::from_pair(self.to_object64, self.to_world64)
    }

    /// The object-to-world matrix in `f64` (column vectors).
    pub fn to_world_matrix(&self) -> DMat4 {
        DMat4::from(self.to_world64)
    }

    /// The world-to-object matrix in `f64` (column vectors).
    pub fn to_object_matrix(&self) -> DMat4 {
        DMat4::from(self.to_object64)
    }

    /// The object-to-world matrix row-major, as [`TransformStep::Matrix`]
    /// takes it: `Transform::from_steps(&[TransformStep::Matrix(t.rows())])`
    /// is `t` again.
    pub fn rows(&self) -> [[f64; 4]; 4] {
        self.to_world_matrix().transpose().to_cols_array_2d()
    }

    /// The world position of the object-space point `p`.
    #[inline]
    pub fn point(&self, p: Point3) -> Point3 {
        self.to_world.transform_point3a(p)
    }

    /// The object-space position of the world point `p`.
    #[inline]
    pub fn inverse_point(&self, p: Point3) -> Point3 {
        self.to_object.transform_point3a(p)
    }

    /// The world vector of the object-space vector `v` (no translation, no
    /// normalisation: lengths scale with the transform).
    #[inline]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.to_world.transform_vector3a(v)
    }

    /// The world unit normal of the object-space normal `n` (any non-zero
    /// length): the inverse transpose of the linear part applied to `n`, then
    /// normalised.
    ///
    /// Unlike [`vector`](Self::vector) this keeps normals perpendicular to the
    /// surface under non-uniform scale and shear, and it keeps their side: for
    /// every v, `normal(n) · vector(v)` has the sign of `n · v`, so an outward
    /// normal stays outward even under a mirroring (negative) scale.
    #[inline]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        (self.normal_matrix * n).normalize()
    }

    /// The world ray of an object-space ray: origin by [`point`](Self::point),
    /// direction by [`vector`](Self::vector), not normalised.
    #[inline]
    pub fn ray(&self, ray: &Ray) -> Ray {
        Ray::timed(
            self.point(ray.origin()),
            self.vector(ray.direction),
            ray.time(),
        )
    }

    /// The world ray `ray` in object space, with a unit-length direction, and
    /// the factor `scale` between distances there and in the world.
    ///
    /// The world point `ray.at(t)` is the object point `object_ray.at(t')` with
    /// **t′ = t · scale**, that is **t = t′ / scale**, where `scale` is the
    /// object-space length of the world direction `ray.direction` (so
    /// `scale = 1` for rigid transforms). When `ray.direction` has unit length,
    /// as lumen's rays do, t is the world distance that hit records store. A
    /// world search interval `(t_min, t_max)` becomes
    /// `(t_min · scale, t_max · scale)` in object space.
    ///
    /// `ray.direction` must be non-zero.
    #[inline]
    pub fn to_object_ray(&self, ray: &Ray) -> (Ray, f32) {
        let origin = self.to_object.transform_point3a(ray.origin());
        let direction = self.to_object.transform_vector3a(ray.direction);
        let scale = direction.length();
        (Ray::timed(origin, direction / scale, ray.time()), scale)
    }

    /// A world box containing the transformed `bounds`: it contains
    /// [`point`](Self::point) of every point of `bounds`, rounding included.
    ///
    /// Computed by Arvo's method (*Graphics Gems*, 1990): each world axis is
    /// the translation plus, per object axis, the smaller and the larger of the
    /// matrix entry times the box's two extents — the exact box of the eight
    /// transformed corners, without transforming them. It is then widened by a
    /// bound on the rounding of both this sum and of `point` (each at most
    /// γ₃ = 3u/(1 − 3u) times the sum of magnitudes, u = 2⁻²⁴; the margin is
    /// 16u times that sum), so that boxes built from it never lose a surface
    /// point to rounding.
    ///
    /// An empty box (any `min > max`, as [`Aabb::EMPTY`]) stays empty; a box
    /// with non-finite bounds gives the whole space.
    pub fn bounds(&self, bounds: &Aabb) -> Aabb {
        if !bounds.min.cmple(bounds.max).all() {
            return Aabb::EMPTY;
        }
        if !(bounds.min.is_finite() && bounds.max.is_finite()) {
            // Arvo's products would give ∞·0 = NaN; the whole space contains
            // any transformed infinite box.
            return Aabb {
                min: Vec3::NEG_INFINITY,
                max: Vec3::INFINITY,
            };
        }
        let m = &self.to_world.matrix3;
        let t = self.to_world.translation;
        let (mut min, mut max, mut magnitude) = (t, t, t.abs());
        for (column, low, high) in [
            (m.x_axis, bounds.min.x, bounds.max.x),
            (m.y_axis, bounds.min.y, bounds.max.y),
            (m.z_axis, bounds.min.z, bounds.max.z),
        ] {
            let (a, b) = (column * low, column * high);
            min += a.min(b);
            max += a.max(b);
            magnitude += a.abs().max(b.abs());
        }
        let margin = magnitude * (8.0 * f32::EPSILON);
        Aabb {
            min: min - margin,
            max: max + margin,
        }
    }
}

impl fmt::Display for Transform {
    /// The object-to-world matrix, row by row.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let rows = self.rows();
        write!(f, "[")?;
        for (i, row) in rows.iter().enumerate() {
            let sep = if i == 0 { "" } else { ", " };
            write!(f, "{sep}[{}, {}, {}, {}]", row[0], row[1], row[2], row[3])?;
        }
        write!(f, "]")
    }
}

/// The matrix of one step, after checking its values.
fn step_matrix(step: &TransformStep) -> Result<DAffine3, String> {
    const AXES: [&str; 3] = ["x", "y", "z"];
    match *step {
        TransformStep::Translate(v) => {
            for (name, &x) in AXES.iter().zip(&v) {
                check_value(&format!("translation {name}"), x)?;
            }
            Ok(DAffine3::from_translation(DVec3::from_array(v)))
        }
        TransformStep::Rotate { axis, degrees } => {
            for (name, &x) in AXES.iter().zip(&axis) {
                check_value(&format!("rotation axis {name}"), x)?;
            }
            check_value("rotation angle", degrees)?;
            let axis = DVec3::from_array(axis);
            let largest = axis.abs().max_element();
            if largest == 0.0 {
                return Err("the rotation axis [0, 0, 0] has zero length".into());
            }
            // Dividing by the largest component first keeps the squared length
            // from underflowing for tiny axes.
            let axis = (axis / largest).normalize();
            Ok(DAffine3::from_mat3(rotation(axis, degrees)))
        }
        TransformStep::Scale(s) => {
            for (name, &x) in AXES.iter().zip(&s) {
                check_value(&format!("scale {name}"), x)?;
                if x == 0.0 {
                    return Err(format!(
                        "scale {name} is 0: a zero scale flattens the object and has no inverse"
                    ));
                }
                if x.abs() < f64::from(f32::MIN_POSITIVE) {
                    return Err(format!(
                        "scale {name} is {x:e}, too close to 0 for f32 (below {:e})",
                        f32::MIN_POSITIVE
                    ));
                }
            }
            Ok(DAffine3::from_scale(DVec3::from_array(s)))
        }
        TransformStep::Matrix(rows) => {
            for (i, row) in rows.iter().enumerate() {
                for (j, &x) in row.iter().enumerate() {
                    check_value(&format!("matrix entry [{i}][{j}]"), x)?;
                }
            }
            if rows[3] != [0.0, 0.0, 0.0, 1.0] {
                let r = rows[3];
                return Err(format!(
                    "the matrix's last row is [{}, {}, {}, {}], but an affine transform's \
                     last row must be [0, 0, 0, 1]",
                    r[0], r[1], r[2], r[3]
                ));
            }
            let column = |j: usize| DVec3::new(rows[0][j], rows[1][j], rows[2][j]);
            Ok(DAffine3::from_cols(
                column(0),
                column(1),
                column(2),
                column(3),
            ))
        }
    }
}

/// Refuses NaN, infinities and magnitudes that `f32` cannot hold.
fn check_value(what: &str, x: f64) -> Result<(), String> {
    if !x.is_finite() {
        Err(format!("{what} is {x}, not a finite number"))
    } else if x.abs() > f64::from(f32::MAX) {
        Err(format!(
            "{what} is {x:e}, beyond the range of f32 (±{:e})",
            f32::MAX
        ))
    } else {
        Ok(())
    }
}

/// The right-handed rotation by `degrees` about the unit `axis` (Rodrigues):
/// R = cos θ·I + sin θ·[k]ₓ + (1 − cos θ)·kkᵀ.
fn rotation(k: DVec3, degrees: f64) -> DMat3 {
    let (sin, cos) = sin_cos_degrees(degrees);
    // Column j is R applied to the basis vector e_j.
    let column = |e: DVec3, kj: f64| cos * e + sin * k.cross(e) + (1.0 - cos) * kj * k;
    DMat3::from_cols(
        column(DVec3::X, k.x),
        column(DVec3::Y, k.y),
        column(DVec3::Z, k.z),
    )
}

/// sin and cos of an angle in degrees, exact at multiples of 90°, so that
/// quarter turns give exact permutation matrices and full turns the identity
/// (`to_radians` would leave cos 90° ≈ 6·10⁻¹⁷).
fn sin_cos_degrees(degrees: f64) -> (f64, f64) {
    // `%` is exact for floating-point numbers: r is the angle reduced into
    // (−360, 360) without rounding.
    let r = degrees % 360.0;
    match r {
        0.0 => (0.0, 1.0),
        90.0 | -270.0 => (1.0, 0.0),
        180.0 | -180.0 => (0.0, -1.0),
        270.0 | -90.0 => (-1.0, 0.0),
        _ => r.to_radians().sin_cos(),
    }
}

/// Whether every entry is finite and within the range of `f32`.
fn fits_f32(m: &DAffine3) -> bool {
    let limit = f64::from(f32::MAX);
    m.to_cols_array()
        .iter()
        .all(|x| x.is_finite() && x.abs() <= limit)
}

fn frobenius(m: &DMat3) -> f64 {
    (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt()
}

fn mat3_to_f32(m: &DMat3) -> Mat3A {
    Mat3A::from_cols(
        m.x_axis.as_vec3a(),
        m.y_axis.as_vec3a(),
        m.z_axis.as_vec3a(),
    )
}

fn to_f32(m: &DAffine3) -> Affine3A {
    Affine3A {
        matrix3: mat3_to_f32(&m.matrix3),
        translation: m.translation.as_vec3a(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Sphere;
    use crate::math::Interval;
    use crate::rng::Rng;
    use TransformStep::{Matrix, Rotate, Scale, Translate};

    fn tf(steps: &[TransformStep]) -> Transform {
        Transform::from_steps(steps).unwrap()
    }

    fn refused(steps: &[TransformStep]) -> TransformError {
        Transform::from_steps(steps).unwrap_err()
    }

    #[track_caller]
    fn assert_close(actual: Vec3, expected: Vec3, tolerance: f32) {
        assert!(
            (actual - expected).abs().max_element() <= tolerance,
            "{actual} is not within {tolerance} of {expected}"
        );
    }

    fn rz(degrees: f64) -> TransformStep {
        Rotate {
            axis: [0.0, 0.0, 1.0],
            degrees,
        }
    }

    fn range(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * rng.next_f64()
    }

    fn random_vec(rng: &mut Rng, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(
            rng.range_f32(lo, hi),
            rng.range_f32(lo, hi),
            rng.range_f32(lo, hi),
        )
    }

    /// One to four random steps of every kind, with scales in ±[0.5, 2] and
    /// shears below 1, so that the condition number stays moderate.
    fn random_steps(rng: &mut Rng) -> Vec<TransformStep> {
        let n = 1 + (rng.next_u32() % 4) as usize;
        (0..n)
            .map(|_| match rng.next_u32() % 4 {
                0 => Translate([0; 3].map(|_| range(rng, -10.0, 10.0))),
                1 => Rotate {
                    axis: [0; 3].map(|_| range(rng, -1.0, 1.0)),
                    degrees: range(rng, -360.0, 360.0),
                },
                2 => Scale([0; 3].map(|_| {
                    let s = range(rng, 0.5, 2.0);
                    if rng.next_u32().is_multiple_of(2) {
                        s
                    } else {
                        -s
                    }
                })),
                _ => {
                    let mut rows = [
                        [1.0, 0.0, 0.0, 0.0],
                        [0.0, 1.0, 0.0, 0.0],
                        [0.0, 0.0, 1.0, 0.0],
                        [0.0, 0.0, 0.0, 1.0],
                    ];
                    // A shear (one off-diagonal entry) and a translation.
                    let (i, j) = match rng.next_u32() % 6 {
                        0 => (0, 1),
                        1 => (0, 2),
                        2 => (1, 0),
                        3 => (1, 2),
                        4 => (2, 0),
                        _ => (2, 1),
                    };
                    rows[i][j] = range(rng, -0.9, 0.9);
                    for row in rows.iter_mut().take(3) {
                        row[3] = range(rng, -5.0, 5.0);
                    }
                    Matrix(rows)
                }
            })
            .collect()
    }

    #[test]
    fn steps_apply_in_the_order_written() {
        let translate = Translate([1.0, 0.0, 0.0]);
        // Translate, then rotate: (1,0,0) → (2,0,0) → (0,2,0).
        let t = tf(&[translate, rz(90.0)]);
        assert_close(t.point(Vec3::X), Vec3::new(0.0, 2.0, 0.0), 1e-6);
        assert_close(
            t.point(Vec3::new(0.0, 0.0, 3.0)),
            Vec3::new(0.0, 1.0, 3.0),
            1e-6,
        );
        // Rotate, then translate: (1,0,0) → (0,1,0) → (1,1,0).
        let r = tf(&[rz(90.0), translate]);
        assert_close(r.point(Vec3::X), Vec3::new(1.0, 1.0, 0.0), 1e-6);
        assert_close(
            r.point(Vec3::new(0.0, 0.0, 3.0)),
            Vec3::new(1.0, 0.0, 3.0),
            1e-6,
        );

        // Three steps: (1,1,0) scaled by 2 → (2,2,0), translated → (3,2,0),
        // rotated 90° about z → (−2,3,0).
        let s = tf(&[Scale([2.0; 3]), translate, rz(90.0)]);
        assert_close(
            s.point(Vec3::new(1.0, 1.0, 0.0)),
            Vec3::new(-2.0, 3.0, 0.0),
            1e-6,
        );
        // Translate first: (2,1,0) → (4,2,0) → (−2,4,0).
        let s = tf(&[translate, Scale([2.0; 3]), rz(90.0)]);
        assert_close(
            s.point(Vec3::new(1.0, 1.0, 0.0)),
            Vec3::new(-2.0, 4.0, 0.0),
            1e-6,
        );
    }

    #[test]
    fn rotation_is_right_handed_about_the_normalised_axis() {
        let about = |axis: [f64; 3], degrees: f64| tf(&[Rotate { axis, degrees }]);
        let y90 = about([0.0, 1.0, 0.0], 90.0);
        assert_close(y90.point(Vec3::X), -Vec3::Z, 1e-7);
        assert_close(y90.point(Vec3::Z), Vec3::X, 1e-7);
        assert_close(about([0.0, 5.0, 0.0], 90.0).point(Vec3::X), -Vec3::Z, 1e-7);
        assert_close(about([0.0, 1.0, 0.0], -90.0).point(Vec3::X), Vec3::Z, 1e-7);
        assert_close(about([0.0, 0.0, 1.0], 90.0).point(Vec3::X), Vec3::Y, 1e-7);
        assert_close(about([1.0, 0.0, 0.0], 90.0).point(Vec3::Y), Vec3::Z, 1e-7);
        assert_close(about([0.0, 0.0, 1.0], 450.0).point(Vec3::X), Vec3::Y, 1e-7);
        // A third of a turn about (1,1,1) cycles x → y → z → x.
        let diagonal = about([1.0, 1.0, 1.0], 120.0);
        assert_close(diagonal.point(Vec3::X), Vec3::Y, 1e-6);
        assert_close(diagonal.point(Vec3::Y), Vec3::Z, 1e-6);
        assert_close(diagonal.point(Vec3::Z), Vec3::X, 1e-6);
        let z30 = about([0.0, 0.0, 1.0], 30.0);
        assert_close(z30.point(Vec3::X), Vec3::new(0.866_025_4, 0.5, 0.0), 1e-6);
    }

    #[test]
    fn normals_stay_perpendicular_under_non_uniform_scale() {
        // The plane x + y = 0 (normal (1,1,0)) stretched 2× along x is the
        // plane x/2 + y = 0, normal (1,2,0)/√5.
        let t = tf(&[Scale([2.0, 1.0, 1.0])]);
        let n = Vec3::new(1.0, 1.0, 0.0);
        let expected = Vec3::new(1.0, 2.0, 0.0) / 5f32.sqrt();
        assert_close(t.normal(n), expected, 1e-6);
        let tangent = t.vector(Vec3::new(1.0, -1.0, 0.0));
        assert!(t.normal(n).dot(tangent).abs() < 1e-6);
        // Transforming the normal as a vector would not do.
        assert!(t.vector(n).normalize().dot(tangent).abs() > 0.5);

        let mut rng = Rng::new(3);
        let shear = Matrix([
            [1.0, 0.7, 0.0, 0.0],
            [0.0, 1.0, -0.4, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let rotate = Rotate {
            axis: [1.0, -2.0, 0.5],
            degrees: 37.0,
        };
        let t = tf(&[
            Scale([3.0, 0.5, 1.5]),
            rotate,
            shear,
            Translate([4.0, 5.0, 6.0]),
        ]);
        for _ in 0..1000 {
            let n = random_vec(&mut rng, -1.0, 1.0);
            if n.length() < 0.1 {
                continue;
            }
            let first = n.cross(random_vec(&mut rng, -1.0, 1.0));
            if first.length() < 0.1 {
                continue;
            }
            let world = t.normal(n);
            assert!((world.length() - 1.0).abs() < 1e-6);
            for tangent in [first, n.cross(first)] {
                let tangent = t.vector(tangent).normalize();
                assert!(world.dot(tangent).abs() < 1e-5, "{world} · {tangent}");
            }
        }
    }

    #[test]
    fn normals_keep_their_side_under_mirroring() {
        let t = tf(&[Scale([-1.0, 1.0, 1.0])]);
        // The unit sphere's outward normal at (1,0,0) sits at (−1,0,0) in the
        // world, where the outward normal is −x.
        assert_close(t.point(Vec3::X), -Vec3::X, 0.0);
        assert_close(t.normal(Vec3::X), -Vec3::X, 0.0);
        let mut rng = Rng::new(5);
        let t = tf(&[Scale([-2.0, 0.5, 1.0]), rz(30.0)]);
        for _ in 0..200 {
            let n = random_vec(&mut rng, -1.0, 1.0);
            let v = random_vec(&mut rng, -1.0, 1.0);
            let dot = n.dot(v);
            if dot.abs() < 1e-3 {
                continue;
            }
            assert_eq!(t.normal(n).dot(t.vector(v)) > 0.0, dot > 0.0);
        }
    }

    /// A bound on the rounding of `f32` point mappings, from the norms of the
    /// exact matrices: each coordinate of A·p + b is off by at most a few
    /// units in the last place of |A||p| + |b|.
    fn mapping_error(m: &DMat4, p: Vec3) -> f32 {
        let a = DMat3::from_mat4(*m);
        let linear = frobenius(&a) as f32;
        let shift = m.w_axis.truncate().length() as f32;
        8.0 * f32::EPSILON * (linear * p.length() + shift)
    }

    #[test]
    fn inverse_round_trips_on_random_transforms() {
        let mut rng = Rng::new(7);
        for _ in 0..500 {
            let t = tf(&random_steps(&mut rng));
            let inv = t.inverse();
            assert_eq!(inv.inverse(), t);
            let product = t.to_world_matrix() * t.to_object_matrix();
            assert!(product.abs_diff_eq(DMat4::IDENTITY, 1e-12), "{product}");
            for _ in 0..10 {
                let p = random_vec(&mut rng, -10.0, 10.0);
                let world = t.point(p);
                // The rounding of the forward mapping, carried through the
                // inverse, plus that of the inverse mapping itself.
                let a_inv = frobenius(&DMat3::from_mat4(t.to_object_matrix())) as f32;
                let tolerance = 2.0
                    * (a_inv * mapping_error(&t.to_world_matrix(), p)
                        + mapping_error(&t.to_object_matrix(), world));
                assert_close(inv.point(world), p, tolerance);
                let v = random_vec(&mut rng, -1.0, 1.0);
                assert_close(inv.vector(t.vector(v)), v, 1e-4);
            }
        }
    }

    #[test]
    fn a_matrix_step_equals_the_same_steps() {
        // Row-major: the translation is the last column.
        let shift = tf(&[Matrix([
            [1.0, 0.0, 0.0, 5.0],
            [0.0, 1.0, 0.0, 6.0],
            [0.0, 0.0, 1.0, 7.0],
            [0.0, 0.0, 0.0, 1.0],
        ])]);
        assert_close(shift.point(Vec3::ZERO), Vec3::new(5.0, 6.0, 7.0), 0.0);
        // x' = −y, y' = x: a quarter turn about z, read row by row.
        let quarter = tf(&[Matrix([
            [0.0, -1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ])]);
        assert_eq!(quarter, tf(&[rz(90.0)]));
        assert_close(quarter.point(Vec3::X), Vec3::Y, 0.0);

        // Scale, rotate, translate written out by hand as T·R·S, with R from
        // glam's own axis-angle rotation.
        let (s, t) = ([2.0, 3.0, 4.0], [5.0, -6.0, 7.0]);
        let axis = DVec3::new(1.0, 2.0, 3.0).normalize();
        let r = DMat3::from_axis_angle(axis, 40f64.to_radians());
        let mut rows = [[0.0; 4]; 4];
        for i in 0..3 {
            for j in 0..3 {
                rows[i][j] = r.col(j)[i] * s[j];
            }
            rows[i][3] = t[i];
        }
        rows[3][3] = 1.0;
        let steps = tf(&[
            Scale(s),
            Rotate {
                axis: [1.0, 2.0, 3.0],
                degrees: 40.0,
            },
            Translate(t),
        ]);
        let matrix = tf(&[Matrix(rows)]);
        assert!(matrix
            .to_world_matrix()
            .abs_diff_eq(steps.to_world_matrix(), 1e-12));
        assert!(matrix
            .to_object_matrix()
            .abs_diff_eq(steps.to_object_matrix(), 1e-12));
        let p = Vec3::new(0.3, -1.2, 2.5);
        assert_close(matrix.point(p), steps.point(p), 1e-5);
        assert_eq!(tf(&[Matrix(steps.rows())]), steps);
    }

    /// The nearest hit of the ellipsoid Σ((x − c)ᵢ/sᵢ)² = 1, in `f64`.
    fn ellipsoid_hit(ray: &Ray, c: DVec3, s: DVec3) -> Option<f64> {
        let o = (ray.origin().as_dvec3() - c) / s;
        let d = ray.direction.as_dvec3() / s;
        let (a, half_b, k) = (d.dot(d), o.dot(d), o.dot(o) - 1.0);
        let disc = half_b * half_b - a * k;
        (disc >= 0.0).then(|| (-half_b - disc.sqrt()) / a)
    }

    #[test]
    fn object_space_hits_match_world_space_hits() {
        let mut rng = Rng::new(11);
        let world_interval = Interval::new(1e-3, f32::INFINITY);
        let unit = Sphere::new(Vec3::ZERO, 1.0);
        let object_hit = |t: &Transform, ray: &Ray| {
            let (object_ray, scale) = t.to_object_ray(ray);
            assert!((object_ray.direction.length() - 1.0).abs() < 1e-6);
            let interval = Interval::new(world_interval.min * scale, world_interval.max * scale);
            unit.hit(&object_ray, interval)
                .map(|t_object| (t_object / scale, t.point(object_ray.at(t_object))))
        };

        // Uniform scale (a sphere of radius s at c), with a rotation that
        // must not change anything.
        for (s, c) in [
            (3.0, [1.0, -2.0, 4.0]),
            (0.25, [0.0, 5.0, 0.0]),
            (1.0, [0.0; 3]),
        ] {
            let t = tf(&[
                Scale([s; 3]),
                Rotate {
                    axis: [0.3, 1.0, -0.2],
                    degrees: 71.0,
                },
                Translate(c),
            ]);
            let world = Sphere::new(Vec3::from_array(c.map(|x| x as f32)), s as f32);
            let (mut hits, mut misses) = (0, 0);
            for _ in 0..2000 {
                let origin = world.center + random_vec(&mut rng, -8.0, 8.0) * world.radius;
                let target = world.center + random_vec(&mut rng, -1.5, 1.5) * world.radius;
                let ray = Ray::new(origin, (target - origin).normalize());
                // Leave out grazing rays and origins near the surface, whose
                // outcome rounding may decide.
                let to_centre = world.center - origin;
                let miss_distance =
                    (to_centre - to_centre.dot(ray.direction) * ray.direction).length();
                if (miss_distance / world.radius - 1.0).abs() < 0.01
                    || (to_centre.length() / world.radius - 1.0).abs() < 0.01
                {
                    continue;
                }
                let expected = world.hit(&ray, world_interval);
                let actual = object_hit(&t, &ray);
                match (expected, actual) {
                    (None, None) => misses += 1,
                    (Some(t_world), Some((t_obj, point))) => {
                        hits += 1;
                        let scale = world.radius + to_centre.length();
                        assert!(
                            (t_world - t_obj).abs() <= 1e-5 * scale,
                            "{t_world} vs {t_obj}"
                        );
                        assert_close(point, ray.at(t_world), 1e-5 * scale);
                    }
                    _ => panic!("world {expected:?}, object {actual:?} for {ray:?}"),
                }
            }
            assert!(hits > 300 && misses > 300, "{hits} hits, {misses} misses");
        }

        // Non-uniform scale: an ellipsoid, solved in the world in f64.
        let (s, c) = (DVec3::new(2.0, 0.5, 1.5), DVec3::new(1.0, -2.0, 3.0));
        let t = tf(&[Scale(s.to_array()), Translate(c.to_array())]);
        let centre = c.as_vec3a();
        let mut hits = 0;
        for _ in 0..2000 {
            let origin = centre + random_vec(&mut rng, -10.0, 10.0);
            if ((origin.as_dvec3() - c) / s).length() < 1.1 {
                continue;
            }
            let target = centre + random_vec(&mut rng, -0.8, 0.8) * s.as_vec3a() / 3f32.sqrt();
            let ray = Ray::new(origin, (target - origin).normalize());
            let expected = ellipsoid_hit(&ray, c, s).expect("aimed inside");
            let (t_obj, point) = object_hit(&t, &ray).expect("aimed inside");
            hits += 1;
            assert!(
                (expected - f64::from(t_obj)).abs() <= 1e-5 * (1.0 + expected),
                "{expected} vs {t_obj}"
            );
            assert_close(point, ray.at(expected as f32), 1e-4);
            // The ellipsoid's normal is the gradient ((x − c)ᵢ/sᵢ²).
            let gradient = ((point.as_dvec3() - c) / (s * s)).normalize().as_vec3a();
            let (object_ray, scale) = t.to_object_ray(&ray);
            let object_point = object_ray.at(t_obj * scale);
            assert_close(t.normal(object_point), gradient, 1e-4);
        }
        assert!(hits > 1000);
    }

    #[test]
    fn bounds_contain_every_transformed_point() {
        let mut rng = Rng::new(13);
        for _ in 0..500 {
            let mut steps = random_steps(&mut rng);
            // Far from the origin too, where rounding is coarser.
            steps.push(Translate([0; 3].map(|_| range(&mut rng, -1e4, 1e4))));
            let t = tf(&steps);
            let a = random_vec(&mut rng, -100.0, 100.0);
            let b = a + random_vec(&mut rng, 0.0, 10.0);
            let bounds = t.bounds(&Aabb { min: a, max: b });
            let inside = |p: Vec3| bounds.min.cmple(p).all() && p.cmple(bounds.max).all();
            for corner in 0..8 {
                let c = Vec3::new(
                    if corner & 1 == 0 { a.x } else { b.x },
                    if corner & 2 == 0 { a.y } else { b.y },
                    if corner & 4 == 0 { a.z } else { b.z },
                );
                assert!(
                    inside(t.point(c)),
                    "corner {} outside {bounds:?}",
                    t.point(c)
                );
            }
            for _ in 0..50 {
                let p = a + random_vec(&mut rng, 0.0, 1.0) * (b - a);
                assert!(inside(t.point(p)), "{} outside {bounds:?}", t.point(p));
            }
        }

        // And not much larger: the cube [−1,1]³ turned 45° about z spans ±√2
        // in x and y.
        let cube = Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::ONE,
        };
        let turned = tf(&[rz(45.0)]).bounds(&cube);
        let r = std::f32::consts::SQRT_2;
        assert_close(turned.max, Vec3::new(r, r, 1.0), 1e-5);
        assert_close(turned.min, Vec3::new(-r, -r, -1.0), 1e-5);

        let empty = tf(&[rz(45.0)]).bounds(&Aabb::EMPTY);
        assert!(empty.min.x > empty.max.x);
    }

    #[test]
    fn bad_values_are_refused_with_the_step_index() {
        let ok = Translate([1.0, 2.0, 3.0]);
        let cases: Vec<(Vec<TransformStep>, usize, &str)> = vec![
            (
                vec![ok, Translate([0.0, f64::NAN, 0.0])],
                1,
                "translation y is NaN",
            ),
            (
                vec![Translate([f64::INFINITY, 0.0, 0.0])],
                0,
                "translation x is inf",
            ),
            (
                vec![ok, ok, Translate([1e39, 0.0, 0.0])],
                2,
                "beyond the range of f32",
            ),
            (
                vec![
                    ok,
                    Rotate {
                        axis: [0.0, 1.0, 0.0],
                        degrees: f64::NAN,
                    },
                ],
                1,
                "rotation angle is NaN",
            ),
            (
                vec![Rotate {
                    axis: [0.0, 1.0, 0.0],
                    degrees: 1e300,
                }],
                0,
                "beyond the range of f32",
            ),
            (
                vec![
                    ok,
                    ok,
                    Rotate {
                        axis: [0.0, 0.0, 0.0],
                        degrees: 30.0,
                    },
                ],
                2,
                "zero length",
            ),
            (
                vec![Rotate {
                    axis: [f64::NEG_INFINITY, 0.0, 0.0],
                    degrees: 30.0,
                }],
                0,
                "rotation axis x is -inf",
            ),
            (vec![Scale([1.0, 0.0, 1.0])], 0, "scale y is 0"),
            (vec![ok, Scale([1.0, 1.0, -0.0])], 1, "scale z is 0"),
            (vec![ok, Scale([f64::NAN, 1.0, 1.0])], 1, "scale x is NaN"),
            (vec![Scale([1e-40, 1e-40, 1e-40])], 0, "too close to 0"),
            (vec![Scale([1e-6, 1.0, 1.0])], 0, "nearly singular"),
            (
                vec![ok, Scale([1e-4, 1.0, 1.0]), Scale([1e-3, 1.0, 1.0])],
                2,
                "together with the steps before it, the matrix is nearly singular",
            ),
            (
                vec![Scale([1e25; 3]), Scale([1e25; 3])],
                1,
                "together with the steps before it, the matrix has entries beyond",
            ),
        ];
        let matrix_cases: Vec<([[f64; 4]; 4], &str)> = vec![
            (
                [
                    [1.0, 2.0, 3.0, 0.0],
                    [2.0, 4.0, 6.0, 0.0],
                    [0.0, 0.0, 1.0, 0.0],
                    [0.0, 0.0, 0.0, 1.0],
                ],
                "singular (determinant 0)",
            ),
            (
                [
                    [1.0, 1.0, 0.0, 0.0],
                    [1.0, 1.0 + 1e-9, 0.0, 0.0],
                    [0.0, 0.0, 1.0, 0.0],
                    [0.0, 0.0, 0.0, 1.0],
                ],
                "nearly singular",
            ),
            (
                [
                    [1.0, 0.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0, 0.0],
                    [0.0, 0.0, 1.0, 0.0],
                    [0.0, 0.0, 1.0, 1.0],
                ],
                "last row is [0, 0, 1, 1]",
            ),
            (
                [
                    [1.0, 0.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0, 0.0],
                    [0.0, 0.0, 1.0, 0.0],
                    [0.0, 0.0, 0.0, 2.0],
                ],
                "must be [0, 0, 0, 1]",
            ),
            (
                [
                    [1.0, 0.0, 0.0, 0.0],
                    [0.0, 1.0, f64::NAN, 0.0],
                    [0.0, 0.0, 1.0, 0.0],
                    [0.0, 0.0, 0.0, 1.0],
                ],
                "matrix entry [1][2] is NaN",
            ),
        ];
        let cases = cases.into_iter().chain(
            matrix_cases
                .into_iter()
                .map(|(rows, text)| (vec![ok, ok, ok, Matrix(rows)], 3, text)),
        );
        for (steps, index, text) in cases {
            let error = refused(&steps);
            assert_eq!(error.index, index, "{error}");
            assert!(error.message.contains(text), "{error} lacks {text:?}");
            assert!(
                error
                    .to_string()
                    .starts_with(&format!("transform[{index}]: ")),
                "{error}"
            );
        }
        // Just inside the limits.
        tf(&[Scale([1e-5, 1.0, 1.0])]);
        tf(&[Scale([1e-30; 3])]);
        tf(&[Translate([3e38, 0.0, 0.0])]);
    }

    #[test]
    fn identity_composition_and_inverse() {
        assert!(Transform::IDENTITY.is_identity());
        assert_eq!(tf(&[]), Transform::IDENTITY);
        assert_eq!(Transform::default(), Transform::IDENTITY);
        assert!(tf(&[rz(360.0)]).is_identity());
        assert!(tf(&[rz(90.0), rz(90.0), rz(-270.0), rz(90.0)]).is_identity());
        assert!(tf(&[Translate([1.5, -2.0, 0.25]), Translate([-1.5, 2.0, -0.25])]).is_identity());
        assert!(!tf(&[Scale([1.0, 1.0, 2.0])]).is_identity());
        assert!(!tf(&[rz(1e-3)]).is_identity());

        let mut rng = Rng::new(17);
        for _ in 0..200 {
            let (first, second) = (random_steps(&mut rng), random_steps(&mut rng));
            let (a, b) = (tf(&first), tf(&second));
            let both = tf(&[first, second].concat());
            let then = a.then(&b).unwrap();
            let compose = b.compose(&a).unwrap();
            for c in [then, compose] {
                assert!(c
                    .to_world_matrix()
                    .abs_diff_eq(both.to_world_matrix(), 1e-9));
                assert!(c
                    .to_object_matrix()
                    .abs_diff_eq(both.to_object_matrix(), 1e-9));
            }
            let round = a.then(&a.inverse()).unwrap();
            assert!(round.to_world_matrix().abs_diff_eq(DMat4::IDENTITY, 1e-12));
        }
        // Order matters.
        let (t, r) = (tf(&[Translate([1.0, 0.0, 0.0])]), tf(&[rz(90.0)]));
        assert_close(
            t.then(&r).unwrap().point(Vec3::X),
            Vec3::new(0.0, 2.0, 0.0),
            1e-6,
        );
        assert_close(
            t.compose(&r).unwrap().point(Vec3::X),
            Vec3::new(1.0, 1.0, 0.0),
            1e-6,
        );

        // Each well-conditioned, the product not.
        let flat = tf(&[Scale([1e-3, 1.0, 1.0])]);
        assert!(flat.then(&flat).is_none());
    }
}
