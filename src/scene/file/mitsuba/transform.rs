//! `<transform>`: translations, rotations, scalings, matrices and
//! look-ats composed in the order written (the first applied first).

use super::spectrum::number;
use super::xml::Element;

pub use crate::scene::file::matrix::*;

/// Three numbers from `value` ("1, 2, 3" or "1 2 3"; one number is used
/// for all three when `one` allows) or from attributes x, y, z (each
/// `default` when absent).
pub fn triple(e: &Element, default: f64, one: bool) -> Result<[f64; 3], String> {
    if let Some(v) = e.attr("value") {
        let t: Vec<&str> = v
            .split([',', ' ', '\t', '\n'])
            .filter(|t| !t.is_empty())
            .collect();
        return match t.len() {
            1 if one => {
                let x = number(t[0])?;
                Ok([x; 3])
            }
            3 => Ok([number(t[0])?, number(t[1])?, number(t[2])?]),
            n => Err(format!(
                "`value` holds {n} numbers; expected 3{}",
                if one { " or 1" } else { "" }
            )),
        };
    }
    let get = |k: &str| e.attr(k).map_or(Ok(default), number);
    Ok([get("x")?, get("y")?, get("z")?])
}

/// Parses a `"x, y, z"` attribute.
fn attr3(e: &Element, name: &str) -> Result<Option<[f64; 3]>, String> {
    let Some(v) = e.attr(name) else {
        return Ok(None);
    };
    let t: Vec<&str> = v
        .split([',', ' ', '\t', '\n'])
        .filter(|t| !t.is_empty())
        .collect();
    if t.len() != 3 {
        return Err(format!("`{name}` must hold 3 numbers, got `{v}`"));
    }
    Ok(Some([number(t[0])?, number(t[1])?, number(t[2])?]))
}

/// One step of a `<transform>`: its matrix, or what is wrong with it.
pub fn step(e: &Element) -> Result<Mat4, String> {
    match e.tag.as_str() {
        "translate" => {
            Ok(translation(triple(e, 0.0, true)?))
        }
        "scale" => {
            Ok(scaling(triple(e, 1.0, true)?))
        }
        "rotate" => {
            let axis = triple(e, 0.0, false)?;
            let angle = number(e.attr("angle").ok_or("<rotate> needs an `angle` in degrees")?)?;
            let [x, y, z] = normalize(axis).ok_or("<rotate> needs a non-zero axis (x, y, z)")?;
            Ok(rotation([x, y, z], angle))
        }
        "matrix" => {
            let v = e.attr("value").ok_or("<matrix> needs a `value` of 16 or 9 numbers")?;
            let t: Vec<f64> = v
                .split([',', ' ', '\t', '\n'])
                .filter(|t| !t.is_empty())
                .map(number)
                .collect::<Result<_, _>>()?;
            let mut m = IDENTITY;
            match t.len() {
                16 => {
                    for i in 0..4 {
                        for j in 0..4 {
                            m[i][j] = t[i * 4 + j];
                        }
                    }
                }
                9 => {
                    for i in 0..3 {
                        for j in 0..3 {
                            m[i][j] = t[i * 3 + j];
                        }
                    }
                }
                n => return Err(format!("<matrix> holds {n} numbers; expected 16 or 9, row by row")),
            }
            Ok(m)
        }
        "lookat" => {
            let origin = attr3(e, "origin")?.ok_or("<lookat> needs an `origin`")?;
            let target = attr3(e, "target")?.ok_or("<lookat> needs a `target`")?;
            look_at(origin, target, attr3(e, "up")?)
        }
        other => Err(format!(
            "<{other}> is no step of a transform; the steps are translate, rotate, scale, matrix, lookat"
        )),
    }
}
