//! Vectors of f64 for the tests that check single-precision geometry
//! against double precision.

use lumen::math::Vec3;

pub type D3 = [f64; 3];

pub fn d3(v: Vec3) -> D3 {
    [v.x as f64, v.y as f64, v.z as f64]
}

pub fn sub(a: D3, b: D3) -> D3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn dot(a: D3, b: D3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: D3, b: D3) -> D3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
