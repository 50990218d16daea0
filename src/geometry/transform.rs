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
        Ray::new(self.point(ray.origin), self.vector(ray.direction))
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
        let origin = self.to_object.transform_point3a(ray.origin);
        let direction = self.to_object.transform_vector3a(ray.direction);
        let scale = direction.length();
        (Ray::new(origin, direction / scale), scale)
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
