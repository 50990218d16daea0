//! 4×4 matrices of f64 for the scene readers of other renderers'
//! formats: placements composed as those files write them.

/// A 4×4 matrix, row by row.
pub type Mat4 = [[f64; 4]; 4];

/// The identity.
pub const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// The turn about `center` that gives a lumen sphere Mitsuba's and
/// pbrt's texture coordinates. Theirs go round the sphere's z (u from +x
/// towards +y, v from −z to +z, the image's top row at +z), lumen's round
/// its y (u from −x towards +z, v from −y to +y): the rotation
/// (x, y, z) → (−x, z, y), its own inverse, takes one onto the other. A
/// sphere without a texture shows it nowhere.
pub fn z_up_sphere([cx, cy, cz]: [f64; 3]) -> Mat4 {
    // translate(c) · turn · translate(−c), written out exactly.
    [
        [-1.0, 0.0, 0.0, 2.0 * cx],
        [0.0, 0.0, 1.0, cy - cz],
        [0.0, 1.0, 0.0, cz - cy],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

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

/// The smallest axis-aligned box around the box `min`–`max` moved by `m`
/// (around its eight corners), as `(min, max)`.
pub fn placed_box(m: &Mat4, min: [f64; 3], max: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let mut b = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for corner in 0..8 {
        let q = std::array::from_fn(|a| if corner >> a & 1 == 1 { max[a] } else { min[a] });
        for (a, v) in point(m, q).into_iter().enumerate() {
            b.0[a] = b.0[a].min(v);
            b.1[a] = b.1[a].max(v);
        }
    }
    b
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

pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
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

/// The translation by `t`.
pub fn translation(t: [f64; 3]) -> Mat4 {
    let mut m = IDENTITY;
    for i in 0..3 {
        m[i][3] = t[i];
    }
    m
}

/// The scaling by `s` per axis.
pub fn scaling(s: [f64; 3]) -> Mat4 {
    let mut m = IDENTITY;
    for i in 0..3 {
        m[i][i] = s[i];
    }
    m
}

/// The rotation by `degrees` about the unit `axis`, counter-clockwise
/// looking down the axis towards the origin.
pub fn rotation([x, y, z]: [f64; 3], degrees: f64) -> Mat4 {
    let (s, c) = degrees.to_radians().sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y, 0.0],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x, 0.0],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// The inverse of affine `m` (last row 0, 0, 0, 1), if it has one.
#[allow(clippy::needless_range_loop)] // cofactors index rows and columns alike
pub fn inverse(m: &Mat4) -> Option<Mat4> {
    let d = det3(m);
    if d == 0.0 || !d.is_finite() || m[3] != [0.0, 0.0, 0.0, 1.0] {
        return None;
    }
    let a = |i: usize, j: usize| m[i][j];
    // The 3×3 part's inverse: its adjugate over the determinant.
    let mut r = IDENTITY;
    for i in 0..3 {
        for j in 0..3 {
            let (i1, i2) = ((j + 1) % 3, (j + 2) % 3);
            let (j1, j2) = ((i + 1) % 3, (i + 2) % 3);
            r[i][j] = (a(i1, j1) * a(i2, j2) - a(i1, j2) * a(i2, j1)) / d;
        }
    }
    let t = [m[0][3], m[1][3], m[2][3]];
    for i in 0..3 {
        r[i][3] = -(r[i][0] * t[0] + r[i][1] * t[1] + r[i][2] * t[2]);
    }
    r.iter().flatten().all(|v| v.is_finite()).then_some(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_inverse_undoes_its_matrix() {
        let m = mul(
            &mul(
                &translation([1.0, -2.0, 3.0]),
                &rotation([0.6, 0.0, 0.8], 37.0),
            ),
            &scaling([2.0, -0.5, 3.0]),
        );
        let i = inverse(&m).unwrap();
        let p = mul(&m, &i);
        for (r, row) in p.iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                let want = if r == c { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-12, "{p:?}");
            }
        }
        assert!(inverse(&scaling([1.0, 0.0, 1.0])).is_none());
    }
}
