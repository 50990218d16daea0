//! The processor's instruction set, chosen at run time: the render loop and
//! the BVH's sphere packets have a version for AVX2 beside the baseline one.

/// The instruction set the render loop is compiled for, chosen at run time.
///
/// The binary targets the architecture's baseline (SSE2 on x86-64, NEON on
/// aarch64) so it runs anywhere; the per-row loop of [`crate::render`], with everything it inlines
/// (camera, path loop, materials, BVH traversal), is compiled a second time
/// for AVX2, FMA and BMI and used when the processor has them. Rust never
/// fuses a multiply and an add by itself, so both versions compute the same
/// floating-point operations and give bit-identical images.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// The architecture's baseline instructions.
    Baseline,
    /// x86-64 with AVX2, FMA, BMI1 and BMI2.
    Avx2,
}

impl Isa {
    /// The best version this processor can run.
    pub fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx2")
                && is_x86_feature_detected!("fma")
                && is_x86_feature_detected!("bmi1")
                && is_x86_feature_detected!("bmi2")
            {
                return Isa::Avx2;
            }
        }
        Isa::Baseline
    }

    /// A short name for reports (`avx2`, or `sse2`/`neon`/`scalar` for the baseline).
    pub fn name(self) -> &'static str {
        match self {
            Isa::Avx2 => "avx2",
            Isa::Baseline if cfg!(target_arch = "x86_64") => "sse2",
            Isa::Baseline if cfg!(target_arch = "aarch64") => "neon",
            Isa::Baseline => "scalar",
        }
    }
}
