//! `<transform>`: translations, rotations, scalings, matrices and
//! look-ats composed in the order written (the first applied first).

use super::spectrum::number;
use super::xml::Element;

/// A 4×4 matrix, row by row.
pub type Mat4 = [[f64; 4]; 4];

/// The identity.
pub const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// a · b.
pub fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

/// The point `p` moved by `m`.
pub fn point(m: &Mat4, p: [f64; 3]) -> [f64; 3] {
    let w = m[3][0] * p[0] + m[3][1] * p[1] + m[3][2] * p[2] + m[3][3];
    [0, 1, 2].map(|i| (m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3]) / w)
}

/// The vector `v` turned by `m`.
pub fn vector(m: &Mat4, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// The determinant of the 3×3 part.
pub fn det3(m: &Mat4) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `v` of unit length, if it has a length.
pub fn normalize(v: [f64; 3]) -> Option<[f64; 3]> {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (l > 0.0 && l.is_finite()).then(|| v.map(|x| x / l))
}

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

/// The look-at matrix: the camera's local +z towards `target`, +y up,
/// +x to the left (Mitsuba's convention).
pub fn look_at(origin: [f64; 3], target: [f64; 3], up: Option<[f64; 3]>) -> Result<Mat4, String> {
    let dir = normalize(sub(target, origin)).ok_or("`origin` and `target` are the same point")?;
    let up = match up.and_then(normalize) {
        Some(u) => u,
        None => any_perpendicular(dir),
    };
    let left = normalize(cross(up, dir)).ok_or("`up` is parallel to the direction looked in")?;
    let new_up = cross(dir, left);
    Ok([
        [left[0], new_up[0], dir[0], origin[0]],
        [left[1], new_up[1], dir[1], origin[1]],
        [left[2], new_up[2], dir[2], origin[2]],
        [0.0, 0.0, 0.0, 1.0],
    ])
}

/// Some unit vector perpendicular to unit `d`.
pub fn any_perpendicular(d: [f64; 3]) -> [f64; 3] {
    let other = if d[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    normalize(cross(d, other)).unwrap_or([0.0, 0.0, 1.0])
}

/// One step of a `<transform>`: its matrix, or what is wrong with it.
pub fn step(e: &Element) -> Result<Mat4, String> {
    match e.tag.as_str() {
        "translate" => {
            let t = triple(e, 0.0, true)?;
            let mut m = IDENTITY;
            for i in 0..3 {
                m[i][3] = t[i];
            }
            Ok(m)
        }
        "scale" => {
            let s = triple(e, 1.0, true)?;
            let mut m = IDENTITY;
            for i in 0..3 {
                m[i][i] = s[i];
            }
            Ok(m)
        }
        "rotate" => {
            let axis = triple(e, 0.0, false)?;
            let angle = number(e.attr("angle").ok_or("<rotate> needs an `angle` in degrees")?)?;
            let [x, y, z] = normalize(axis).ok_or("<rotate> needs a non-zero axis (x, y, z)")?;
            let (s, c) = angle.to_radians().sin_cos();
            let t = 1.0 - c;
            Ok([
                [t * x * x + c, t * x * y - s * z, t * x * z + s * y, 0.0],
                [t * x * y + s * z, t * y * y + c, t * y * z - s * x, 0.0],
                [t * x * z - s * y, t * y * z + s * x, t * z * z + c, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ])
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
