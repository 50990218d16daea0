//! pbrt's participating media as lumen's `[media]`: `MakeNamedMedium`
//! (the `homogeneous` and `uniformgrid` kinds; the others with
//! `--approximate`), the media
//! `MediumInterface` sets on the shapes that follow (carried by their
//! materials) and the one the camera stands in.

use super::lex::At;
use super::params::{Params, Problem, Spectral};
use super::scene::Builder;
use crate::scene::desc::{
    BoxDesc, EdgeDesc, FieldDesc, MediumDesc, ScaleDesc, TransformDesc, VoxelsDesc,
};
use crate::scene::file::matrix;

/// The kinds of medium pbrt-v4 has; lumen reads the first two.
const KINDS: &[&str] = &["homogeneous", "uniformgrid", "rgbgrid", "cloud", "nanovdb"];

/// The largest |g| lumen's phase function takes
/// ([`MAX_ASYMMETRY`](crate::phase::MAX_ASYMMETRY)).
const MAX_G: f64 = 0.999;

impl Builder {
    /// `MakeNamedMedium "name"` (at `at`) with parameters `p`.
    pub(super) fn named_medium(&mut self, name: &str, at: At, p: &Params) -> Result<(), Problem> {
        if self.desc.media.contains_key(name) {
            return Err((at, format!("the medium `{name}` is defined twice"), None));
        }
        let (kind, kat) = p.string_of("type", "string")?.ok_or((
            at,
            "a medium needs a \"string type\"".into(),
            None,
        ))?;
        let kind = kind.to_string();
        let mut known = vec![
            "type", "sigma_a", "sigma_s", "scale", "g", "preset", "Le", "Lescale",
        ];
        let mut bounds = None;
        let mut density = None;
        match kind.as_str() {
            "homogeneous" => {}
            "uniformgrid" => {
                known.extend(["density", "nx", "ny", "nz", "p0", "p1", "temperature"]);
                density = Some(self.density(p, at)?);
                if let Some((_, tat)) = p.nums("temperature", &["float"])? {
                    self.lacks(
                        tat,
                        "medium that gives off light (`temperature`)",
                        "no light from it",
                    )?;
                }
            }
            "rgbgrid" | "cloud" | "nanovdb" => {
                // Whatever describes the density: the medium's own σa and
                // σs, filling its box, stand for it.
                known.extend([
                    "density",
                    "nx",
                    "ny",
                    "nz",
                    "p0",
                    "p1",
                    "temperature",
                    "temperaturescale",
                    "temperatureoffset",
                    "filename",
                    "density_scale",
                    "wavelength",
                ]);
                self.lacks(
                    kat,
                    &format!("`{kind}` medium (a density that varies)"),
                    "a medium of its sigma_a and sigma_s at density 1 throughout its box",
                )?;
                bounds = self.medium_box(p)?;
            }
            other => {
                return Err((
                    kat,
                    format!(
                        "no medium kind is called `{other}`; pbrt has {}",
                        KINDS.join(", ")
                    ),
                    None,
                ))
            }
        }
        if let Some((preset, pat)) = p.string_of("preset", "string")? {
            self.lacks(
                pat,
                &format!("table of measured media (`preset` \"{preset}\")"),
                "sigma_a and sigma_s as given (1 by default)",
            )?;
        }
        if let Some((le, lat)) = p.spectral("Le", false)? {
            if !matches!(le, Spectral::Grey(v) if v == 0.0) {
                self.lacks(
                    lat,
                    "medium that gives off light (`Le`)",
                    "no light from it",
                )?;
            }
        }
        let sigma_a = coefficient(p, "sigma_a")?;
        let sigma_s = coefficient(p, "sigma_s")?;
        let scale = p.float("scale")?.unwrap_or(1.0);
        let g = p.float("g")?.unwrap_or(0.0);
        let at_of = |n: &str| p.get(n).map_or(at, |q| q.at);
        if !(scale.is_finite() && scale >= 0.0) {
            return Err((
                at_of("scale"),
                format!("`scale` must be ≥ 0, got {scale}"),
                None,
            ));
        }
        if !(g.abs() <= MAX_G) {
            return Err((
                at_of("g"),
                format!("`g` must lie between −{MAX_G} and {MAX_G}, got {g}"),
                None,
            ));
        }
        p.ignore(&known);
        p.finish(&format!("a `{kind}` medium"), &known)?;
        let sigma_t: [f64; 3] = std::array::from_fn(|c| sigma_a[c] + sigma_s[c]);
        let albedo: [f64; 3] = std::array::from_fn(|c| {
            if sigma_t[c] > 0.0 {
                sigma_s[c] / sigma_t[c]
            } else {
                0.0
            }
        });
        let field = |c: [f64; 3]| {
            if c[0] == c[1] && c[1] == c[2] {
                FieldDesc::Value(c[0])
            } else {
                FieldDesc::Color(c)
            }
        };
        let (sigma_t, scale) = match density {
            None => (field(sigma_t), scale),
            // σt is the density times σa + σs: a grey sum goes with the
            // scale, a coloured one makes the grid's voxels RGB.
            Some(mut voxels) => {
                if let FieldDesc::Value(sum) = field(sigma_t) {
                    (FieldDesc::Voxels(voxels), scale * sum)
                } else {
                    voxels.values = (voxels.values.iter())
                        .flat_map(|d| sigma_t.map(|s| d * s))
                        .collect();
                    (FieldDesc::Voxels(voxels), scale)
                }
            }
        };
        self.desc.media.insert(
            name.to_string(),
            MediumDesc {
                sigma_t,
                albedo: field(albedo),
                scale: (scale != 1.0).then_some(scale),
                bounds,
                g: (g != 0.0).then_some(g),
            },
        );
        Ok(())
    }

    /// A `uniformgrid` medium's density: `nx` × `ny` × `nz` values (x
    /// fastest) over the box `p0`–`p1` of the medium's space, 0 beyond the
    /// outer voxels as pbrt reads it.
    fn density(&self, p: &Params, at: At) -> Result<VoxelsDesc, Problem> {
        let Some((values, dat)) = p.nums("density", &["float"])? else {
            return Err((
                at,
                "a uniformgrid medium needs its \"float density\" values".into(),
                None,
            ));
        };
        let mut size = [1u32; 3];
        for (a, n) in ["nx", "ny", "nz"].into_iter().enumerate() {
            if let Some(v) = p.int(n)? {
                size[a] = u32::try_from(v).ok().filter(|&v| v > 0).ok_or((
                    p.get(n).map_or(at, |q| q.at),
                    format!("`{n}` must be at least 1, got {v}"),
                    None,
                ))?;
            }
        }
        let count = size.iter().map(|&n| u64::from(n)).product::<u64>();
        if values.len() as u64 != count {
            return Err((
                dat,
                format!(
                    "the grid has {} density values where nx × ny × nz = {count}",
                    values.len()
                ),
                None,
            ));
        }
        if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err((
                dat,
                format!("a density must be finite and ≥ 0, got {v}"),
                None,
            ));
        }
        let p0 = p.triple("p0", &["point3", "point"])?.unwrap_or([0.0; 3]);
        let p1 = p.triple("p1", &["point3", "point"])?.unwrap_or([1.0; 3]);
        if (0..3).any(|a| !(p1[a] > p0[a])) {
            return Err((
                at,
                format!("`p1` {p1:?} must lie above `p0` {p0:?} on every axis"),
                None,
            ));
        }
        let mut transform = vec![
            TransformDesc::Scale(ScaleDesc::PerAxis(std::array::from_fn(|a| p1[a] - p0[a]))),
            TransformDesc::Translate(p0),
        ];
        if self.state.ctm != matrix::IDENTITY {
            transform.push(TransformDesc::Matrix(self.state.ctm));
        }
        Ok(VoxelsDesc {
            voxels: size,
            values: values.to_vec(),
            transform,
            edge: Some(EdgeDesc::Zero),
        })
    }

    /// The box `p0`–`p1` of a grid medium, placed by the current
    /// transform (the box around its corners).
    fn medium_box(&self, p: &Params) -> Result<Option<BoxDesc>, Problem> {
        let p0 = p.triple("p0", &["point3", "point"])?.unwrap_or([0.0; 3]);
        let p1 = p.triple("p1", &["point3", "point"])?.unwrap_or([1.0; 3]);
        let (min, max) = matrix::placed_box(&self.state.ctm, p0, p1);
        Ok(Some(BoxDesc { min, max }))
    }

    /// `MediumInterface "inside" "outside"` (one name: both sides), at
    /// `at`: the media the shapes that follow separate, and the camera's
    /// (the outside one when `Camera` comes). "" is no medium.
    pub(super) fn medium_interface(&mut self, inside: String, outside: String, at: At) {
        let name = |n: String| (!n.is_empty()).then_some(n);
        for n in [&inside, &outside] {
            if !n.is_empty() {
                self.medium_uses.push((n.clone(), at));
            }
        }
        self.state.media = [name(inside), name(outside)];
    }

    /// Material `material` with the current media on its sides, when
    /// they differ (a surface between the same medium on both sides is no
    /// boundary of it, in pbrt: it leaves a ray in the medium it is in).
    pub(super) fn in_media(&mut self, material: String) -> String {
        let [inside, outside] = self.state.media.clone();
        if inside == outside {
            return material;
        }
        let interface = self.state.interface;
        let counter = &mut self.counter;
        self.media_copies.of(
            &mut self.desc,
            material,
            [inside, outside],
            interface,
            |desc, stem| loop {
                *counter += 1;
                let name = format!("{stem}-{counter}");
                if !desc.materials.contains_key(&name) {
                    return name;
                }
            },
        )
    }

    /// Every medium named by `MediumInterface` is defined (pbrt resolves
    /// the names once the whole file is read).
    pub(super) fn check_media(&self) -> Result<(), Problem> {
        for (name, at) in &self.medium_uses {
            if !self.desc.media.contains_key(name) {
                let mut known: Vec<&str> = self.desc.media.keys().map(String::as_str).collect();
                known.sort_unstable();
                let defined = if known.is_empty() {
                    "no medium is defined".to_string()
                } else {
                    format!("the media are {}", known.join(", "))
                };
                return Err((*at, format!("no medium is named `{name}`; {defined}"), None));
            }
        }
        Ok(())
    }
}

/// A medium's coefficient `name` per channel (1 when absent, as pbrt's):
/// a number, an RGB triple or a sampled spectrum (reduced to RGB as a
/// conductor's index is).
fn coefficient(p: &Params, name: &str) -> Result<[f64; 3], Problem> {
    let c = match p.spectral(name, false)? {
        None => return Ok([1.0; 3]),
        Some((Spectral::Grey(v), _)) => ([v; 3], p.get(name).expect("given").at),
        Some((Spectral::Rgb(c), at)) => (c, at),
        Some((Spectral::Samples(v), at)) => {
            let (w, x): (Vec<f64>, Vec<f64>) = v.chunks_exact(2).map(|q| (q[0], q[1])).unzip();
            if w.windows(2).any(|q| q[1] <= q[0]) {
                return Err((at, "a spectrum's wavelengths must increase".into(), None));
            }
            (
                crate::scene::file::mitsuba::spectrum::list_to_srgb(&w, &x, false, true),
                at,
            )
        }
        Some((_, at)) => {
            return Err((
                at,
                format!("a medium's `{name}` is a number, an \"rgb\" or a sampled \"spectrum\""),
                None,
            ))
        }
    };
    let (c, at) = c;
    if c.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err((
            at,
            format!("`{name}` must be finite and ≥ 0, got {c:?}"),
            None,
        ));
    }
    Ok(c)
}
