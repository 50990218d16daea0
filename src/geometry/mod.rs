//! Shapes that rays can hit, the record of a hit, and the acceleration
//! structure that finds the nearest one.

pub mod bvh;
pub mod bvh_build;
pub mod bvh_bundle;
pub mod hit;
pub mod instance;
pub mod primitive;
pub mod quad;
pub mod quadric;
pub mod sphere;
pub mod transform;
pub mod triangle;

pub use bvh::Bvh;
pub use bvh_bundle::RayBundle;
pub use hit::HitRecord;
pub use instance::Instance;
pub use primitive::{Kind, Primitive, PrimitiveSet};
pub use quad::Quad;
pub use quadric::{Quadric, QuadricForm};
pub use sphere::Sphere;
pub use triangle::Triangle;
