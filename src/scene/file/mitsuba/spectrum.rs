//! Colours as Mitsuba 3's RGB variants read them: `<rgb>` as written,
//! `<spectrum>` values reduced to linear sRGB (a wavelength:value list
//! integrated against the CIE 1931 observer, reflectances under D65), and
//! the named indices of refraction.

use super::cie;

/// What a colour is for: Mitsuba reads a spectrum differently for each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Use {
    /// A reflectance or transmittance: within [0, 1], spectra weighted by
    /// D65.
    Reflectance,
    /// Emitted light: not bounded above, spectra as they are; a uniform
    /// spectrum is the sRGB of equal energy, slightly purple.
    Emission,
    /// Any other quantity (an index of refraction, a roughness): not
    /// bounded, spectra under D65.
    Unbounded,
}

/// XYZ to linear sRGB (Rec. 709 primaries, D65 white).
const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.240479, -1.537150, -0.498535],
    [-0.969256, 1.875991, 0.041556],
    [0.055648, -0.204043, 1.057311],
];

/// 1 / ∫ȳ dλ over the table.
const Y_NORMALIZATION: f64 = 1.0 / 106.750_259_399_414_06;
/// 1 / D65's mean over the table.
const D65_NORMALIZATION: f64 = 1.0 / 98.997_417_518_762_55;

fn xyz_to_srgb(xyz: [f64; 3]) -> [f64; 3] {
    XYZ_TO_SRGB.map(|row| row[0] * xyz[0] + row[1] * xyz[1] + row[2] * xyz[2])
}

/// Table `t` (of [`cie::SAMPLES`] entries from [`cie::FIRST`]) at
/// wavelength `w`, linearly interpolated; 0 outside the table.
fn table(t: &[f64], w: f64) -> f64 {
    if !(cie::FIRST..=cie::LAST).contains(&w) {
        return 0.0;
    }
    let x = (w - cie::FIRST) * (cie::SAMPLES - 1) as f64 / (cie::LAST - cie::FIRST);
    let i = (x as usize).min(cie::SAMPLES - 2);
    let f = x - i as f64;
    t[i] * (1.0 - f) + t[i + 1] * f
}

/// The linear sRGB of the piecewise-linear spectrum through
/// (`wavelengths`, `values`) (nm, increasing), zero outside them; under
/// D65 when `d65`; clamped to [0, 1] when `bounded`, else at 0.
pub fn list_to_srgb(wavelengths: &[f64], values: &[f64], bounded: bool, d65: bool) -> [f64; 3] {
    const STEPS: usize = 1000;
    let (first, last) = (wavelengths[0], wavelengths[wavelengths.len() - 1]);
    let mut xyz = [0.0f64; 3];
    for i in 0..STEPS {
        let w = cie::FIRST + (i as f64 / (STEPS - 1) as f64) * (cie::LAST - cie::FIRST);
        if w < first || w > last {
            continue;
        }
        let k = wavelengths
            .partition_point(|x| *x <= w)
            .saturating_sub(1)
            .min(wavelengths.len() - 2);
        let f = (w - wavelengths[k]) / (wavelengths[k + 1] - wavelengths[k]);
        let mut v = values[k] * (1.0 - f) + values[k + 1] * f;
        if d65 {
            v *= table(&cie::D65, w) * D65_NORMALIZATION;
        }
        for (c, x) in xyz.iter_mut().enumerate() {
            *x += table(&cie::XYZ[c * cie::SAMPLES..(c + 1) * cie::SAMPLES], w) * v;
        }
    }
    let scale = (cie::LAST - cie::FIRST) * Y_NORMALIZATION / STEPS as f64;
    let rgb = xyz_to_srgb(xyz.map(|x| x * scale));
    if bounded {
        rgb.map(|c| c.clamp(0.0, 1.0))
    } else {
        rgb.map(|c| c.max(0.0))
    }
}

/// A `<spectrum value="…"/>` for `use_`: one number (a uniform
/// spectrum) or wavelength:value pairs; `Err` says what is wrong.
pub fn parse(value: &str, use_: Use) -> Result<[f64; 3], String> {
    let tokens: Vec<&str> = value
        .split([',', ' ', '\t', '\n'])
        .filter(|t| !t.is_empty())
        .collect();
    if tokens.len() == 1 && !tokens[0].contains(':') {
        let v = number(tokens[0])?;
        return Ok(match use_ {
            // The equal-energy spectrum seen in sRGB, whose white is D65.
            Use::Emission => xyz_to_srgb([v, v, v]),
            _ => [v; 3],
        });
    }
    let mut wavelengths = Vec::with_capacity(tokens.len());
    let mut values = Vec::with_capacity(tokens.len());
    for t in &tokens {
        let Some((w, v)) = t.split_once(':') else {
            return Err(format!(
                "`{t}` is not a wavelength:value pair (write \"400:0.5, 500:0.8\" or one number)"
            ));
        };
        let w = number(w)?;
        if let Some(last) = wavelengths.last() {
            if w <= *last {
                return Err(format!("wavelengths must increase: {w} after {last}"));
            }
        }
        wavelengths.push(w);
        values.push(number(v)?);
    }
    if wavelengths.len() < 2 {
        return Err("a spectrum needs at least two wavelength:value pairs".into());
    }
    Ok(match use_ {
        Use::Reflectance => list_to_srgb(&wavelengths, &values, true, true),
        Use::Emission => list_to_srgb(&wavelengths, &values, false, false),
        Use::Unbounded => list_to_srgb(&wavelengths, &values, false, true),
    })
}

/// A finite number.
pub fn number(t: &str) -> Result<f64, String> {
    match t.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("expected a finite number, got {v}")),
        Err(_) => Err(format!("expected a number, got `{}`", t.trim())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectra_reduce_as_mitsuba_reduces_them() {
        // Values of Mitsuba 3's own routine for these spectra.
        let close = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 2e-4);
        let flat = parse("360:1, 830:1", Use::Reflectance).unwrap();
        assert!(close(flat, [0.99899, 0.99887, 0.99880]), "{flat:?}");
        let flat = parse("360:1, 830:1", Use::Emission).unwrap();
        assert!(close(flat, [1.20488, 0.94823, 0.90927]), "{flat:?}");
        let ramp = parse("400:0.5, 500:0.8", Use::Reflectance).unwrap();
        assert!(close(ramp, [0.0, 0.022437, 0.719299]), "{ramp:?}");
        let ramp = parse("400:0.5, 500:0.8", Use::Emission).unwrap();
        assert!(close(ramp, [0.0, 0.016869, 0.655922]), "{ramp:?}");
        // A uniform emitted spectrum is equal-energy white seen in sRGB.
        let uniform = parse("2", Use::Emission).unwrap();
        assert!(close(
            uniform,
            [2.0 * 1.204794, 2.0 * 0.948291, 2.0 * 0.908916]
        ));
        assert_eq!(parse("0.5", Use::Reflectance).unwrap(), [0.5; 3]);
    }

    #[test]
    fn malformed_spectra_are_refused() {
        for bad in [
            "400:0.5",
            "500:1, 400:1",
            "400:x, 500:1",
            "nan",
            "400-0.5, 500:1",
        ] {
            assert!(parse(bad, Use::Reflectance).is_err(), "{bad}");
        }
    }
}
