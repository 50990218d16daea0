//! pbrt-v4's spectra reduced to linear sRGB as its RGB film sees them:
//! named glasses by their index of refraction, named metals from lumen's
//! table of conductors, and light spectra (a blackbody, a sampled
//! spectrum, a standard illuminant) by their colour at luminance 1, since
//! pbrt scales every light whose spectrum is not RGB to the luminance its
//! `scale` gives.

use crate::scene::file::mitsuba::spectrum::list_to_srgb;

/// The named glasses of pbrt-v4 and their index of refraction at the
/// helium d line (587.6 nm), from Schott's catalogue.
const GLASSES: &[(&str, f64)] = &[
    ("glass-BK7", 1.5168),
    ("glass-BAF10", 1.6700),
    ("glass-FK51A", 1.4866),
    ("glass-LASF9", 1.8503),
    ("glass-F5", 1.6727),
    ("glass-F10", 1.7283),
    ("glass-F11", 1.7847),
];

/// The metals pbrt-v4 names (`metal-Au-eta`, `metal-Au-k`) that lumen's
/// table of conductors has, by the name pbrt uses.
const METALS: &[&str] = &["Ag", "Al", "Au", "Cu", "CuZn", "MgO", "TiO2"];

/// The index of refraction of named glass `name`.
pub fn glass(name: &str) -> Option<f64> {
    GLASSES.iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
}

/// The names of the glasses, for messages.
pub fn glass_names() -> Vec<&'static str> {
    GLASSES.iter().map(|&(n, _)| n).collect()
}

/// For `metal-X-eta` or `metal-X-k`: the metal `X` in lumen's table and
/// whether it is the `k` part.
pub fn metal(name: &str) -> Result<(&'static str, bool), String> {
    let (metal, part) = name
        .strip_prefix("metal-")
        .and_then(|rest| rest.rsplit_once('-'))
        .ok_or_else(|| {
            format!(
                "`{name}` names no metal and no spectrum file: lumen reads pbrt's named metal spectra (metal-Au-eta, metal-Au-k, …) and files of wavelength–value pairs"
            )
        })?;
    let k = match part {
        "eta" => false,
        "k" => true,
        _ => {
            return Err(format!(
                "`{name}`: a metal's spectrum is its -eta or its -k"
            ))
        }
    };
    match METALS.iter().find(|m| **m == metal) {
        Some(m) => Ok((m, k)),
        None => Err(format!(
            "metal `{metal}` is not among lumen's conductors; lumen has {}",
            METALS
                .iter()
                .map(|m| format!("metal-{m}"))
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

/// Luminance of linear sRGB.
fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// `c` scaled to luminance 1.
fn unit_luminance(c: [f64; 3]) -> Option<[f64; 3]> {
    let y = luminance(c);
    (y > 0.0 && y.is_finite()).then(|| c.map(|x| x / y))
}

/// The colour of a blackbody at `kelvin`, at luminance 1.
pub fn blackbody(kelvin: f64) -> Option<[f64; 3]> {
    if !(kelvin > 0.0 && kelvin.is_finite()) {
        return None;
    }
    // Planck's law; its scale does not matter.
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    const KB: f64 = 1.380_649e-23;
    let wavelengths: Vec<f64> = (0..=94).map(|i| 360.0 + 5.0 * f64::from(i)).collect();
    let values: Vec<f64> = wavelengths
        .iter()
        .map(|nm| {
            let l = nm * 1e-9;
            2.0 * H * C * C / (l.powi(5) * ((H * C / (l * KB * kelvin)).exp() - 1.0))
        })
        .collect();
    let peak = values.iter().cloned().fold(0.0, f64::max);
    let values: Vec<f64> = values.iter().map(|v| v / peak).collect();
    unit_luminance(list_to_srgb(&wavelengths, &values, false, false))
}

/// The colour of the light spectrum through `pairs` (wavelength, value,
/// …), at luminance 1.
pub fn light_samples(pairs: &[f64]) -> Result<[f64; 3], String> {
    let (w, v): (Vec<f64>, Vec<f64>) = pairs.chunks_exact(2).map(|p| (p[0], p[1])).unzip();
    if w.len() < 2 || w.windows(2).any(|p| p[1] <= p[0]) {
        return Err("a spectrum's wavelengths must increase, two at least".into());
    }
    unit_luminance(list_to_srgb(&w, &v, false, false))
        .ok_or_else(|| "the spectrum gives no visible light".into())
}

/// The colour of a reflectance spectrum through `pairs`, under D65.
pub fn reflectance_samples(pairs: &[f64]) -> Result<[f64; 3], String> {
    let (w, v): (Vec<f64>, Vec<f64>) = pairs.chunks_exact(2).map(|p| (p[0], p[1])).unzip();
    if w.len() < 2 || w.windows(2).any(|p| p[1] <= p[0]) {
        return Err("a spectrum's wavelengths must increase, two at least".into());
    }
    Ok(list_to_srgb(&w, &v, true, true))
}

/// A named illuminant's colour at luminance 1 (pbrt's D65 is sRGB's white).
pub fn illuminant(name: &str) -> Option<[f64; 3]> {
    (name == "stdillum-D65").then_some([1.0; 3])
}

/// Whether `name` is one of the spectra pbrt names that lumen reads (a
/// glass, a metal's part, a standard illuminant), which a file of the same
/// name does not replace, as in pbrt.
pub fn is_named(name: &str) -> bool {
    glass(name).is_some() || metal(name).is_ok() || illuminant(name).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blackbodies_have_pbrts_colours() {
        // pbrt-v4's colours of a blackbody at luminance 1, from its CIE
        // tables (its film adds no white balance).
        for (t, want) in [
            (2700.0, [1.935, 0.804, 0.192]),
            (5000.0, [1.213, 0.961, 0.763]),
            (6500.0, [1.043, 0.984, 1.035]),
            (10000.0, [0.872, 0.995, 1.431]),
        ] {
            let got = blackbody(t).unwrap();
            for c in 0..3 {
                assert!(
                    (got[c] - want[c]).abs() < 0.02,
                    "{t} K: {got:?} vs {want:?}"
                );
            }
        }
        assert!(blackbody(0.0).is_none());
    }

    #[test]
    fn named_metals_and_glasses_are_found() {
        assert_eq!(metal("metal-Au-eta"), Ok(("Au", false)));
        assert_eq!(metal("metal-TiO2-k"), Ok(("TiO2", true)));
        assert_eq!(metal("metal-CuZn-k"), Ok(("CuZn", true)));
        assert!(metal("metal-Zn-k").unwrap_err().contains("metal-CuZn"));
        assert!(metal("metal-Au").is_err());
        assert_eq!(glass("glass-BK7"), Some(1.5168));
        for m in METALS {
            assert!(crate::material::metals::find(m).is_some(), "{m}");
        }
    }
}
