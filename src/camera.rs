//! The positionable camera with defocus blur.
//!
//! The camera sits at `lookfrom` and looks at `lookat`. Its orientation is the
//! orthonormal basis (u, v, w): w = unit(lookfrom − lookat) points backwards,
//! u = unit(vup × w) to the right, v = w × u up. The viewport lies on the focus
//! plane, `focus_dist` in front of the camera, and is 2·tan(vfov/2)·focus_dist
//! high. Rays start from a random point of the defocus disk (the lens) and pass
//! through a random point of their pixel, so only the focus plane is sharp.
//!
//! An orthographic camera instead sends parallel rays along −w from the
//! points of a rectangle through `lookfrom`, of the height its projection
//! gives and the image's aspect: a view without perspective, in which size
//! does not change with distance.

use crate::math::{Point3, Vec3};
use crate::ray::Ray;
use crate::sampler::{Dim, Sampler};
use crate::sampling;
use thiserror::Error;

/// Everything that places and shapes the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSettings {
    /// Vertical field of view in degrees, in (0, 180).
    pub vfov: f32,
    /// Eye position.
    pub lookfrom: Point3,
    /// Point looked at.
    pub lookat: Point3,
    /// "Up" direction; need not be orthogonal to the view direction.
    pub vup: Vec3,
    /// Angle in degrees of the cone from a pixel on the focus plane to the lens.
    /// Zero gives a pinhole camera (everything sharp).
    pub defocus_angle: f32,
    /// Distance from `lookfrom` to the plane in perfect focus.
    pub focus_dist: f32,
    /// The times `[open, close]` the shutter opens and closes, within
    /// [0, 1]; each ray is traced at a time drawn uniformly between them
    /// (at `open` when they are equal).
    pub shutter: [f32; 2],
    /// Mirror the image left to right (a left-handed camera).
    pub mirror: bool,
    /// Rays start this far in front of the lens along the view direction
    /// (nothing nearer is seen); 0: at the lens.
    pub near_clip: f32,
    /// Nothing farther than this along the view direction is seen (camera
    /// rays end on that plane); ∞: no limit.
    pub far_clip: f32,
    /// The image is the window `[x, y, …]` of a full image of
    /// `[…, width, height]` pixels; `None`: the whole image.
    pub crop: Option<[u32; 4]>,
    /// Perspective (framed by `vfov`) or orthographic.
    pub projection: Projection,
}

/// How the camera maps the scene onto the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Rays from the lens through the image plane, `vfov` high.
    Perspective,
    /// Parallel rays along the view direction from the points of a
    /// rectangle through `lookfrom`, `height` high in scene units (its
    /// width follows the image's aspect); `vfov` does not apply.
    Orthographic {
        /// The height of the rectangle seen.
        height: f32,
    },
}

impl Default for CameraSettings {
    fn default() -> Self {
        Self {
            vfov: 90.0,
            lookfrom: Vec3::ZERO,
            lookat: Vec3::new(0.0, 0.0, -1.0),
            vup: Vec3::Y,
            defocus_angle: 0.0,
            focus_dist: 1.0,
            shutter: [0.0, 0.0],
            mirror: false,
            near_clip: 0.0,
            far_clip: f32::INFINITY,
            crop: None,
            projection: Projection::Perspective,
        }
    }
}

/// A camera that cannot be built.
#[derive(Debug, Error, PartialEq)]
pub enum CameraError {
    /// The field of view is not in (0, 180) degrees.
    #[error("vfov must be greater than 0 and less than 180 degrees, got {0}")]
    FieldOfView(f32),
    /// The eye and the target coincide, so there is no view direction.
    #[error("lookfrom and lookat are the same point {0}: the camera has no view direction")]
    NoViewDirection(Point3),
    /// The up vector is parallel to the view direction (or zero).
    #[error("vup {0} is parallel to the view direction: the camera cannot tell up from sideways")]
    UpParallelToView(Vec3),
    /// The focus distance is not positive.
    #[error("focus_dist must be positive, got {0}")]
    FocusDistance(f32),
    /// The defocus angle is outside [0, 180).
    #[error("defocus_angle must be at least 0 and less than 180 degrees, got {0}")]
    DefocusAngle(f32),
    /// The image has no pixels.
    #[error("image size {0}x{1} has no pixels")]
    EmptyImage(u32, u32),
    /// The set-up's numbers are too large for `f32` arithmetic.
    #[error("lookfrom, lookat and focus_dist are too large for f32 arithmetic (keep them below about 1e18)")]
    Overflow,
    /// Neighbouring pixels' rays are closer than `f32` can tell apart at
    /// the camera's coordinates: the rays would coincide (or vanish, and
    /// every sample be NaN).
    #[error(
        "focus_dist {focus_dist:e} with vfov {vfov} puts neighbouring pixels {step:e} apart at \
         coordinates up to {scale:e}, closer than f32 can tell apart: make focus_dist at least \
         {needed:e} (left out, it is the distance to lookat)"
    )]
    Unresolved {
        /// The focus distance given.
        focus_dist: f32,
        /// The field of view given.
        vfov: f32,
        /// The distance between neighbouring pixels in the focus plane.
        step: f32,
        /// The largest coordinate of the camera and its focus plane.
        scale: f32,
        /// The smallest focus distance that resolves the pixels.
        needed: f32,
    },
    /// A value is NaN or infinite.
    #[error("camera {0} is not a finite number")]
    NotFinite(&'static str),
    /// The shutter interval is not within [0, 1] or closes before it opens.
    #[error("shutter must be [open, close] with 0 <= open <= close <= 1, got [{0}, {1}]")]
    Shutter(f32, f32),
    #[error("a {1}x{2} window at ({x}, {y}) does not fit a {w}x{h} image", x = .0[0], y = .0[1], w = .0[2], h = .0[3])]
    /// A crop window `[x, y, full width, full height]` that the image of
    /// the given width and height does not fit.
    Crop([u32; 4], u32, u32),
    #[error("near_clip must be finite and not negative, got {0}")]
    /// A negative or non-finite near clipping distance.
    NearClip(f32),
    #[error("far_clip must be beyond near_clip ({1}), got {0}")]
    /// A far clipping distance not beyond the near one.
    FarClip(f32, f32),
    /// An orthographic view's height is not positive and finite.
    #[error("ortho_height must be a positive finite number, got {0}")]
    OrthoHeight(f32),
    /// An orthographic camera given a lens.
    #[error("an orthographic camera has no lens: defocus_angle must be 0, got {0}")]
    OrthographicLens(f32),
    /// An orthographic view so small that neighbouring pixels' rays
    /// coincide in `f32` at the camera's coordinates.
    #[error(
        "ortho_height {height:e} puts neighbouring pixels {step:e} apart at coordinates up to \
         {scale:e}, closer than f32 can tell apart: make it larger or move the scene nearer \
         the origin"
    )]
    OrthographicUnresolved {
        /// The height given.
        height: f32,
        /// The distance between neighbouring pixels.
        step: f32,
        /// The largest coordinate of the viewed rectangle.
        scale: f32,
    },
}

/// A camera ready to generate rays for an image of a given size.
#[derive(Clone, Debug)]
pub struct Camera {
    center: Point3,
    pixel00: Point3,
    pixel_du: Vec3,
    pixel_dv: Vec3,
    defocus_u: Vec3,
    defocus_v: Vec3,
    /// When the shutter opens, and for how long.
    shutter_open: f32,
    shutter_span: f32,
    /// The orthonormal basis (u, v, w).
    pub basis: [Vec3; 3],
    /// Where about its pixel a camera ray goes.
    filter: crate::filter::PixelFilter,
    /// How far in front of the lens rays start.
    near_clip: f32,
    /// How far in front of the lens they end.
    far_clip: f32,
    /// Orthographic: every ray's direction, from its point of the image
    /// rectangle.
    parallel: Option<Vec3>,
}

impl Camera {
    /// The camera with its rays spread about their pixels by `filter`
    /// (a box, each pixel's square, when not set).
    pub fn with_filter(mut self, filter: crate::filter::PixelFilter) -> Self {
        self.filter = filter;
        self
    }

    /// Builds the camera for a `width`×`height` image, refusing impossible set-ups.
    pub fn new(settings: &CameraSettings, width: u32, height: u32) -> Result<Self, CameraError> {
        let s = settings;
        for (name, ok) in [
            ("vfov", s.vfov.is_finite()),
            ("lookfrom", s.lookfrom.is_finite()),
            ("lookat", s.lookat.is_finite()),
            ("vup", s.vup.is_finite()),
            ("defocus_angle", s.defocus_angle.is_finite()),
            ("focus_dist", s.focus_dist.is_finite()),
            ("shutter", s.shutter.iter().all(|t| t.is_finite())),
        ] {
            if !ok {
                return Err(CameraError::NotFinite(name));
            }
        }
        // First, as the default focus distance (to `lookat`) is then 0 too:
        // the message names what is really wrong.
        let view = s.lookfrom - s.lookat;
        if view == Vec3::ZERO {
            return Err(CameraError::NoViewDirection(s.lookfrom));
        }
        let ortho_height = match s.projection {
            Projection::Perspective => None,
            Projection::Orthographic { height } => Some(height),
        };
        match ortho_height {
            None if !(s.vfov > 0.0 && s.vfov < 180.0) => {
                return Err(CameraError::FieldOfView(s.vfov))
            }
            Some(h) if !(h > 0.0 && h.is_finite()) => return Err(CameraError::OrthoHeight(h)),
            Some(_) if s.defocus_angle != 0.0 => {
                return Err(CameraError::OrthographicLens(s.defocus_angle))
            }
            _ => {}
        }
        if ortho_height.is_none() && !(s.focus_dist > 0.0) {
            return Err(CameraError::FocusDistance(s.focus_dist));
        }
        if !(s.defocus_angle >= 0.0 && s.defocus_angle < 180.0) {
            return Err(CameraError::DefocusAngle(s.defocus_angle));
        }
        let [open, close] = s.shutter;
        if !(0.0 <= open && open <= close && close <= 1.0) {
            return Err(CameraError::Shutter(open, close));
        }
        if width == 0 || height == 0 {
            return Err(CameraError::EmptyImage(width, height));
        }
        if !(s.near_clip >= 0.0 && s.near_clip.is_finite()) {
            return Err(CameraError::NearClip(s.near_clip));
        }
        if !(s.far_clip > s.near_clip) {
            return Err(CameraError::FarClip(s.far_clip, s.near_clip));
        }
        if !view.length_squared().is_finite() {
            return Err(CameraError::Overflow);
        }
        let w = view.normalize();
        let side = s.vup.cross(w);
        // Parallel (or zero) vup: the cross product vanishes relative to |vup|.
        if side.length_squared() <= 1e-12 * s.vup.length_squared().max(f32::MIN_POSITIVE) {
            return Err(CameraError::UpParallelToView(s.vup));
        }
        let u = side.normalize();
        let v = w.cross(u);
        // Mirrored, the image's x runs the other way; up stays up.
        let u = if s.mirror { -u } else { u };

        // A cropped image is a window of the full one, framed as it.
        let [x0, y0, full_width, full_height] = match s.crop {
            None => [0, 0, width, height],
            Some([x, y, fw, fh])
                if x.checked_add(width).is_some_and(|e| e <= fw)
                    && y.checked_add(height).is_some_and(|e| e <= fh) =>
            {
                [x, y, fw, fh]
            }
            Some(crop) => return Err(CameraError::Crop(crop, width, height)),
        };
        let h = (s.vfov.to_radians() / 2.0).tan();
        // An orthographic view's rectangle passes through the eye.
        let (viewport_height, plane_dist) = match ortho_height {
            None => (2.0 * h * s.focus_dist, s.focus_dist),
            Some(height) => (height, 0.0),
        };
        let viewport_width = viewport_height * (full_width as f32 / full_height as f32);
        let viewport_u = viewport_width * u;
        let viewport_v = -viewport_height * v; // image rows go down
        let pixel_du = viewport_u / full_width as f32;
        let pixel_dv = viewport_v / full_height as f32;
        let upper_left = s.lookfrom - plane_dist * w - viewport_u / 2.0 - viewport_v / 2.0;
        let pixel00 =
            upper_left + 0.5 * (pixel_du + pixel_dv) + x0 as f32 * pixel_du + y0 as f32 * pixel_dv;
        let defocus_radius = s.focus_dist * (s.defocus_angle.to_radians() / 2.0).tan();
        let derived = [u, v, w, pixel_du, pixel_dv, pixel00];
        if !(derived.iter().all(|d| d.is_finite()) && defocus_radius.is_finite()) {
            return Err(CameraError::Overflow);
        }
        // A pixel's ray aims at its point of the focus plane, whose
        // coordinates are rounded to within ε/2 of the largest (`scale`):
        // for neighbouring pixels to get rays of their own, the points must
        // be further apart than that. Two units of ε·scale leave a margin
        // for the rounding of the sums that place them. Coordinates count as
        // at least 1e-12 in size: the squares taken to normalise a ray's
        // direction must stay within f32's normal range (tiny directions
        // normalise to NaN).
        let corners = [
            s.lookfrom,
            upper_left,
            upper_left + viewport_u,
            upper_left + viewport_v,
            upper_left + viewport_u + viewport_v,
        ];
        let scale = corners
            .iter()
            .map(|c| c.abs().max_element())
            .fold(1e-12, f32::max);
        // Largest components, not lengths: their squares could underflow.
        let step = pixel_du
            .abs()
            .max_element()
            .min(pixel_dv.abs().max_element());
        let resolution = 2.0 * f32::EPSILON * scale;
        if !(step > resolution) {
            return Err(match ortho_height {
                Some(height) => CameraError::OrthographicUnresolved {
                    height,
                    step,
                    scale,
                },
                None => CameraError::Unresolved {
                    focus_dist: s.focus_dist,
                    vfov: s.vfov,
                    step,
                    scale,
                    // The step grows with the focus distance; where it has
                    // vanished, pixels are 2h / height apart per unit of
                    // focus distance, the largest component at least 1/√3
                    // of that.
                    needed: 1.01
                        * if step > 1e-30 {
                            s.focus_dist * (resolution / step)
                        } else {
                            resolution * 3f32.sqrt() / (2.0 * h / height as f32)
                        },
                },
            });
        }
        Ok(Camera {
            center: s.lookfrom,
            pixel00,
            pixel_du,
            pixel_dv,
            defocus_u: defocus_radius * u,
            defocus_v: defocus_radius * v,
            shutter_open: open,
            shutter_span: close - open,
            basis: [u, v, w],
            filter: crate::filter::PixelFilter::Box,
            near_clip: s.near_clip,
            far_clip: s.far_clip,
            parallel: ortho_height.map(|_| -w),
        })
    }

    /// Whether camera rays end at a far clipping plane.
    #[inline]
    pub fn clips_far(&self) -> bool {
        self.far_clip < f32::INFINITY
    }

    /// The distance along camera ray `ray` (as [`Camera::ray`] makes it)
    /// to the far clipping plane: ∞ without one (∞ over the cosine).
    #[inline]
    pub fn far(&self, ray: &Ray) -> f32 {
        // From the near plane (or the lens) along the ray, over the cosine
        // to the view.
        (self.far_clip - self.near_clip) / -ray.direction.dot(self.basis[2])
    }

    /// The ray from the centre of the lens through the centre of pixel
    /// `(x, y)`, as the shutter opens: the axis of the pixel's camera rays.
    #[inline]
    pub fn central_ray(&self, x: u32, y: u32) -> Ray {
        let target = self.pixel00 + x as f32 * self.pixel_du + y as f32 * self.pixel_dv;
        match self.parallel {
            Some(direction) => Ray::timed(target, direction, self.shutter_open),
            None => Ray::timed(
                self.center,
                (target - self.center).normalize(),
                self.shutter_open,
            ),
        }
    }

    /// The ray through pixel `(x, y)` at sub-pixel offset `(dx, dy)` ∈ [-0.5, 0.5)²
    /// from the pixel centre, leaving the lens at a point and at a time in
    /// the shutter interval drawn from `sampler`.
    #[inline]
    pub fn ray(&self, x: u32, y: u32, dx: f32, dy: f32, sampler: &mut impl Sampler) -> Ray {
        let (dx, dy) = (self.filter.offset(dx), self.filter.offset(dy));
        let target =
            self.pixel00 + (x as f32 + dx) * self.pixel_du + (y as f32 + dy) * self.pixel_dv;
        let (origin, direction) = match self.parallel {
            Some(direction) => (target, direction),
            None => {
                let origin = if self.defocus_u == Vec3::ZERO {
                    self.center
                } else {
                    let p = sampling::in_unit_disk(sampler, Dim::Lens);
                    self.center + p.x * self.defocus_u + p.y * self.defocus_v
                };
                (origin, (target - origin).normalize())
            }
        };
        let time = if self.shutter_span > 0.0 {
            self.shutter_open + self.shutter_span * sampler.get_1d(Dim::Time)
        } else {
            self.shutter_open
        };
        let origin = if self.near_clip > 0.0 {
            // On the near plane: its distance over the cosine to the view.
            origin + direction * (self.near_clip / -direction.dot(self.basis[2]))
        } else {
            origin
        };
        Ray::timed(origin, direction, time)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn settings() -> CameraSettings {
        CameraSettings {
            vfov: 90.0,
            lookfrom: Vec3::new(0.0, 0.0, 0.0),
            lookat: Vec3::new(0.0, 0.0, -1.0),
            vup: Vec3::Y,
            defocus_angle: 0.0,
            focus_dist: 1.0,
            shutter: [0.0, 0.0],
            mirror: false,
            near_clip: 0.0,
            far_clip: f32::INFINITY,
            crop: None,
            projection: Projection::Perspective,
        }
    }

    #[test]
    fn a_mirrored_camera_sees_the_image_flipped_left_to_right() {
        let s = CameraSettings {
            lookfrom: Vec3::new(3.0, 2.0, 1.0),
            lookat: Vec3::new(0.0, 0.5, -1.0),
            vfov: 40.0,
            ..settings()
        };
        let plain = Camera::new(&s, 64, 48).unwrap();
        let mirrored = Camera::new(&CameraSettings { mirror: true, ..s }, 64, 48).unwrap();
        let [u, v, w] = mirrored.basis;
        assert!((u.cross(v) + w).length() < 1e-6, "left-handed");
        assert!(v.y > 0.0, "up stays up");
        for (x, y) in [(0, 0), (5, 40), (63, 47), (31, 10)] {
            let a = mirrored.central_ray(x, y).direction;
            let b = plain.central_ray(63 - x, y).direction;
            assert!((a - b).length() < 1e-5, "pixel ({x}, {y}): {a} vs {b}");
        }
        assert!(
            (mirrored.central_ray(0, 0).direction - plain.central_ray(0, 0).direction).length()
                > 0.1
        );
    }

    /// A focus plane so close that the pixels' points round together is
    /// refused (it made every ray NaN and the image black), and the focus
    /// distance the message asks for works.
    #[test]
    fn focus_planes_closer_than_f32_resolves_are_refused() {
        let mut s = settings();
        s.lookfrom = Vec3::new(3.0, 2.0, 1.0);
        s.lookat = Vec3::ZERO;
        for focus_dist in [1e-30, 1e-9, 1e-6] {
            s.focus_dist = focus_dist;
            let Err(CameraError::Unresolved { needed, .. }) = Camera::new(&s, 400, 300) else {
                panic!("focus_dist {focus_dist} accepted");
            };
            assert!(needed > focus_dist && needed < 1e-3, "{needed}");
            s.focus_dist = needed;
            let camera = Camera::new(&s, 400, 300).expect("the distance asked for works");
            let mut rng = crate::rng::Rng::new(1);
            for (x, y) in [(0, 0), (200, 150), (399, 299)] {
                let ray = camera.ray(x, y, 0.3, -0.2, &mut rng);
                assert!(ray.direction.is_finite(), "{focus_dist}: {ray:?}");
                let next = camera.ray(x + 1, y, 0.3, -0.2, &mut rng);
                assert_ne!(ray.direction, next.direction, "pixels told apart");
            }
        }
        // At the origin, a tiny focus plane makes directions too short to
        // normalise.
        s.lookfrom = Vec3::ZERO;
        s.lookat = Vec3::new(0.0, 0.0, -1.0);
        s.focus_dist = 1e-30;
        let Err(CameraError::Unresolved { needed, .. }) = Camera::new(&s, 400, 300) else {
            panic!("a focus plane at 1e-30 accepted");
        };
        s.focus_dist = needed;
        let camera = Camera::new(&s, 400, 300).expect("the distance asked for works");
        let ray = camera.ray(0, 0, 0.3, -0.2, &mut crate::rng::Rng::new(1));
        assert!(ray.direction.is_finite() && ray.direction.length() > 0.99);
        // Far from the origin the bound grows with the coordinates.
        s.lookfrom = Vec3::new(1e6, 0.0, 0.0);
        s.focus_dist = 1.0;
        assert!(matches!(
            Camera::new(&s, 4000, 3000),
            Err(CameraError::Unresolved { .. })
        ));
        s.focus_dist = 1e3;
        assert!(Camera::new(&s, 4000, 3000).is_ok());
    }

    #[test]
    fn basis_is_orthonormal_and_right_handed() {
        let s = CameraSettings {
            lookfrom: Vec3::new(13.0, 2.0, 3.0),
            lookat: Vec3::ZERO,
            ..settings()
        };
        let cam = Camera::new(&s, 400, 225).unwrap();
        let [u, v, w] = cam.basis;
        for a in [u, v, w] {
            assert!((a.length() - 1.0).abs() < 1e-6);
        }
        assert!(u.dot(v).abs() < 1e-6 && v.dot(w).abs() < 1e-6 && u.dot(w).abs() < 1e-6);
        assert!((u.cross(v) - w).length() < 1e-6);
        assert!((w - s.lookfrom.normalize()).length() < 1e-6);
        assert!(v.y > 0.0, "v points up");
    }

    #[test]
    fn centre_pixel_looks_at_the_target_and_corners_span_the_fov() {
        let cam = Camera::new(&settings(), 2, 2).unwrap();
        let mut rng = Rng::new(0);
        // Between the four pixels of a 2x2 image lies the view direction.
        let r = cam.ray(0, 0, 0.5, 0.5, &mut rng);
        assert!((r.direction - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        // The top-left corner of a 90° square view is at 45° up and left.
        let corner = cam.ray(0, 0, -0.5, -0.5, &mut rng);
        let expected = Vec3::new(-1.0, 1.0, -1.0).normalize();
        assert!((corner.direction - expected).length() < 1e-6);
    }

    #[test]
    fn impossible_cameras_are_refused() {
        let bad = |s: CameraSettings| Camera::new(&s, 10, 10).unwrap_err();
        assert_eq!(
            bad(CameraSettings {
                vfov: 180.0,
                ..settings()
            }),
            CameraError::FieldOfView(180.0)
        );
        assert_eq!(
            bad(CameraSettings {
                vfov: 0.0,
                ..settings()
            }),
            CameraError::FieldOfView(0.0)
        );
        assert!(matches!(
            bad(CameraSettings {
                lookat: Vec3::ZERO,
                ..settings()
            }),
            CameraError::NoViewDirection(_)
        ));
        assert!(matches!(
            bad(CameraSettings {
                vup: Vec3::Z,
                ..settings()
            }),
            CameraError::UpParallelToView(_)
        ));
        assert!(matches!(
            bad(CameraSettings {
                focus_dist: 0.0,
                ..settings()
            }),
            CameraError::FocusDistance(_)
        ));
    }

    #[test]
    fn defocus_rays_start_on_the_lens_and_meet_on_the_focus_plane() {
        let s = CameraSettings {
            defocus_angle: 10.0,
            focus_dist: 3.0,
            ..settings()
        };
        let cam = Camera::new(&s, 10, 10).unwrap();
        let mut rng = Rng::new(1);
        let radius = 3.0 * (5.0f32).to_radians().tan();
        let reference = cam.ray(4, 6, 0.0, 0.0, &mut rng);
        let focus_point = reference.at(3.0 / -reference.direction.z);
        for _ in 0..100 {
            let r = cam.ray(4, 6, 0.0, 0.0, &mut rng);
            assert!(r.origin().length() <= radius * 1.0001);
            let p = r.at(3.0 / -r.direction.z);
            assert!((p - focus_point).length() < 1e-4);
        }
    }

    #[test]
    fn a_crop_window_sees_what_the_full_image_sees_there() {
        let full = Camera::new(&settings(), 64, 48).unwrap();
        let crop = Camera::new(
            &CameraSettings {
                crop: Some([40, 10, 64, 48]),
                ..settings()
            },
            16,
            20,
        )
        .unwrap();
        for (x, y) in [(0, 0), (15, 0), (0, 19), (7, 11)] {
            let (a, b) = (crop.central_ray(x, y), full.central_ray(40 + x, 10 + y));
            assert!((a.direction - b.direction).length() < 1e-6, "({x}, {y})");
        }
        for bad in [[50, 10, 64, 48], [40, 30, 64, 48], [u32::MAX, 0, 64, 48]] {
            let s = CameraSettings {
                crop: Some(bad),
                ..settings()
            };
            assert_eq!(
                Camera::new(&s, 16, 20).unwrap_err(),
                CameraError::Crop(bad, 16, 20)
            );
        }
    }

    #[test]
    fn rays_start_on_the_near_plane() {
        let s = CameraSettings {
            near_clip: 0.5,
            ..settings()
        };
        let camera = Camera::new(&s, 32, 32).unwrap();
        let mut rng = Rng::new(5);
        for (x, y) in [(0, 0), (31, 31), (16, 3)] {
            let ray = camera.ray(x, y, 0.5, 0.5, &mut rng);
            let depth = (ray.origin() - s.lookfrom).dot((s.lookat - s.lookfrom).normalize());
            assert!((depth - 0.5).abs() < 1e-6, "({x}, {y}): {depth}");
        }
        for bad in [-1.0, f32::NAN] {
            let s = CameraSettings {
                near_clip: bad,
                ..settings()
            };
            assert!(matches!(
                Camera::new(&s, 4, 4),
                Err(CameraError::NearClip(_))
            ));
        }
    }

    /// An orthographic camera's rays all run along the view, from the
    /// points of a rectangle through the eye of the height asked and the
    /// image's aspect, the clipping planes measured along them.
    #[test]
    fn orthographic_rays_are_parallel_from_a_rectangle_of_the_height_asked() {
        let s = CameraSettings {
            lookfrom: Vec3::new(1.0, 2.0, 3.0),
            lookat: Vec3::new(1.0, 2.0, -5.0),
            near_clip: 0.25,
            far_clip: 10.25,
            projection: Projection::Orthographic { height: 3.0 },
            ..settings()
        };
        let (width, height) = (40, 30);
        let camera = Camera::new(&s, width, height).unwrap();
        let mut rng = Rng::new(3);
        let view = Vec3::new(0.0, 0.0, -1.0);
        let mut low = Vec3::splat(f32::INFINITY);
        let mut high = Vec3::splat(f32::NEG_INFINITY);
        for (x, y, dx, dy) in [
            (0, 0, -0.5, -0.5),
            (39, 29, 0.4999, 0.4999),
            (20, 15, 0.0, 0.0),
        ] {
            let ray = camera.ray(x, y, dx, dy, &mut rng);
            assert!((ray.direction - view).length() < 1e-6, "{ray:?}");
            let o = ray.origin();
            assert!(
                (o.z - (3.0 - 0.25)).abs() < 1e-5,
                "starts on the near plane: {o}"
            );
            assert!((camera.far(&ray) - 10.0).abs() < 1e-5);
            low = low.min(o);
            high = high.max(o);
        }
        // The corners span 4 × 3 about the eye; image rows run down.
        assert!((high.x - low.x - 4.0).abs() < 1e-3 && (high.y - low.y - 3.0).abs() < 1e-3);
        assert!((0.5 * (low + high) - Vec3::new(1.0, 2.0, 2.75)).length() < 1e-3);
        let top_left = camera.ray(0, 0, -0.5, -0.5, &mut rng).origin();
        assert!(top_left.x < 0.0 && top_left.y > 3.0, "{top_left}");
        let centre = camera.central_ray(20, 15);
        assert_eq!(centre.direction, view);
        for (projection, defocus_angle, expected) in [
            (0.0, 0.0, CameraError::OrthoHeight(0.0)),
            (f32::INFINITY, 0.0, CameraError::OrthoHeight(f32::INFINITY)),
            (1.0, 2.0, CameraError::OrthographicLens(2.0)),
        ] {
            let bad = CameraSettings {
                projection: Projection::Orthographic { height: projection },
                defocus_angle,
                ..s
            };
            assert_eq!(Camera::new(&bad, 4, 4).unwrap_err(), expected);
        }
        let tiny = CameraSettings {
            lookfrom: Vec3::new(1e6, 0.0, 0.0),
            lookat: Vec3::new(1e6, 0.0, -1.0),
            projection: Projection::Orthographic { height: 1e-3 },
            ..s
        };
        assert!(matches!(
            Camera::new(&tiny, 400, 300),
            Err(CameraError::OrthographicUnresolved { .. })
        ));
    }
}
