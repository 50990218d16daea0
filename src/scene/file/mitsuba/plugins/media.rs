//! Mitsuba's participating media as lumen's `[media]`: `homogeneous` and
//! `heterogeneous` media with `constvolume` and `gridvolume` volumes and
//! the isotropic and Henyey–Greenstein (`hg`) phase functions, and the media a shape names inside and
//! outside it, carried by its material.

use super::super::props::{Colour, Props};
use super::super::spectrum::Use;
use super::super::xml::Element;
use super::{Convert, Failure};
use crate::scene::desc::{BoxDesc, FieldDesc, GridDesc, MediumDesc, TransformDesc};

/// The media and volumes lumen reads, for messages.
const MEDIA: &[&str] = &["homogeneous", "heterogeneous"];
const VOLUMES: &[&str] = &["constvolume", "gridvolume"];

/// The unit cube, where Mitsuba's volumes lie before their `to_world`.
const UNIT_CUBE: BoxDesc = BoxDesc {
    min: [0.0; 3],
    max: [1.0; 3],
};

impl<'d> Convert<'d> {
    /// The medium of `<medium>` element `e` (converted once): its name in
    /// `[media]`.
    pub(super) fn medium(&mut self, e: &'d Element) -> Result<String, Failure> {
        let key = e as *const Element;
        if let Some(name) = self.media.get(&key) {
            return Ok(name.clone());
        }
        if e.tag != "medium" {
            return Err(self.fail(
                e,
                format!("a shape's medium is a <medium>, got <{}>", e.tag),
            ));
        }
        let t = self.type_of(e)?;
        if !MEDIA.contains(&t) {
            return Err(self.unknown_type(e, "medium", MEDIA));
        }
        let p = Props::of(e, self)?;
        let mut g = None;
        for phase in p.objects("phase") {
            match self.type_of(phase)? {
                "isotropic" => Props::of(phase, self)?.finish(&[], self)?,
                "hg" => {
                    let q = Props::of(phase, self)?;
                    // Mitsuba's default asymmetry.
                    g = Some(q.float("g", self)?.unwrap_or(0.8));
                    q.finish(&["g"], self)?;
                }
                kind => self.lacks(
                    phase,
                    &format!("the phase function `{kind}` (lumen has `isotropic` and `hg`)"),
                    "the isotropic one",
                )?,
            }
        }
        let scale = p.float("scale", self)?;
        // Whether light is sampled from inside the medium: the image is the
        // same either way.
        let _ = p.boolean("sample_emitters", self)?;
        let heterogeneous = t == "heterogeneous";
        let (sigma_t, bounds) = self.quantity(&p, "sigma_t", 1.0, heterogeneous)?;
        let (albedo, _) = self.quantity(&p, "albedo", 0.75, heterogeneous)?;
        let mut known = vec!["sigma_t", "albedo", "scale", "sample_emitters"];
        if heterogeneous {
            let _ = p.boolean("has_spectral_extinction", self)?;
            known.push("has_spectral_extinction");
        }
        p.finish(&known, self)?;
        let desc = MediumDesc {
            sigma_t,
            albedo,
            scale,
            bounds,
            g,
        };
        let name = match e.attr("id") {
            Some(id) if !self.desc.media.contains_key(id) => id.to_string(),
            _ => self.name("medium"),
        };
        self.desc.media.insert(name.clone(), desc);
        self.media.insert(key, name.clone());
        Ok(name)
    }

    /// Medium parameter `n` of `p` (`default` where absent), and the box a
    /// heterogeneous medium fills when it is its extinction: its volume's
    /// (a plain value is a constant volume over the unit cube, as in
    /// Mitsuba; a grid's box is the one lumen gives it).
    fn quantity(
        &mut self,
        p: &Props<'d>,
        n: &str,
        default: f64,
        heterogeneous: bool,
    ) -> Result<(FieldDesc, Option<BoxDesc>), Failure> {
        let boxed = |b: BoxDesc| heterogeneous.then_some(b);
        if let Some(v) = p.peek(n).filter(|v| v.tag == "volume") {
            p.take(n);
            return self.volume(v, boxed);
        }
        let value = match p.colour(n, Use::Unbounded, self)? {
            None => FieldDesc::Value(default),
            Some(Colour::Rgb(c)) => FieldDesc::Color(c),
            Some(Colour::Texture(t)) => {
                return Err(self.fail(
                    t,
                    format!("a medium's `{n}` is a number, a colour or a <volume>, not a texture"),
                ))
            }
        };
        Ok((value, boxed(UNIT_CUBE)))
    }

    /// A `<volume>` as a medium quantity, and its box (through `boxed`).
    fn volume(
        &mut self,
        v: &'d Element,
        boxed: impl Fn(BoxDesc) -> Option<BoxDesc>,
    ) -> Result<(FieldDesc, Option<BoxDesc>), Failure> {
        let t = self.type_of(v)?;
        let p = Props::of(v, self)?;
        let to_world = p.transform("to_world", self)?;
        match t {
            "constvolume" => {
                let value = match p.colour("value", Use::Unbounded, self)? {
                    None => FieldDesc::Value(1.0),
                    Some(Colour::Rgb(c)) => FieldDesc::Color(c),
                    Some(Colour::Texture(t)) => {
                        return Err(self.fail(t, "a constvolume's `value` is a colour".into()))
                    }
                };
                p.finish(&["value", "to_world"], self)?;
                let b = to_world.map_or(UNIT_CUBE, |m| {
                    let (min, max) = crate::scene::file::matrix::placed_box(&m, [0.0; 3], [1.0; 3]);
                    BoxDesc { min, max }
                });
                Ok((value, boxed(b)))
            }
            "gridvolume" => {
                let (name, at) = p
                    .string_at("filename", self)?
                    .ok_or_else(|| self.fail(v, "a gridvolume needs a `filename`".into()))?;
                let file = self.file(name, at)?;
                if p.boolean("use_grid_bbox", self)? == Some(true) {
                    self.lacks(v, "use_grid_bbox", "the unit cube its to_world places")?;
                }
                match p.string("filter_type", self)? {
                    None | Some("trilinear") => {}
                    Some(other) => self.lacks(
                        v,
                        &format!("filter_type `{other}`"),
                        "trilinear interpolation",
                    )?,
                }
                match p.string("wrap_mode", self)? {
                    None | Some("clamp") => {}
                    Some(other) => self.lacks(v, &format!("wrap_mode `{other}`"), "clamping")?,
                }
                let _ = p.boolean("raw", self)?;
                let _ = p.boolean("accel", self)?;
                p.finish(
                    &[
                        "filename",
                        "to_world",
                        "use_grid_bbox",
                        "filter_type",
                        "wrap_mode",
                        "raw",
                        "accel",
                    ],
                    self,
                )?;
                let transform = to_world.map_or(Vec::new(), |m| vec![TransformDesc::Matrix(m)]);
                Ok((
                    FieldDesc::Grid(GridDesc {
                        grid: file,
                        transform,
                    }),
                    None,
                ))
            }
            _ => Err(self.unknown_type(v, "volume", VOLUMES)),
        }
    }

    /// The material `material` with the media `interior` and `exterior`
    /// (names in `[media]`) on its sides; `null`: the shape's BSDF is
    /// Mitsuba's `null`, which bounds media as an interface.
    pub(super) fn with_media(
        &mut self,
        material: String,
        interior: Option<String>,
        exterior: Option<String>,
        null: bool,
    ) -> String {
        let counter = &mut self.counter;
        self.bounded.of(
            &mut self.desc,
            material,
            [interior, exterior],
            null,
            |_, stem| {
                *counter += 1;
                format!("{stem}-{counter}")
            },
        )
    }
}
