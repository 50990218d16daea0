//! Statistics shared by the unit tests of the sampling routines.

/// Pearson's χ² of `counts` against `expected` counts, cells expected to
/// hold fewer than 5 pooled into one; and the degrees of freedom (the
/// cells counted, less one).
pub(crate) fn chi_square(counts: &[u64], expected: &[f64]) -> (f64, usize) {
    let (mut chi2, mut cells, mut pooled_n, mut pooled_e) = (0.0, 0usize, 0.0, 0.0);
    for (&n, &e) in counts.iter().zip(expected) {
        if e < 5.0 {
            pooled_n += n as f64;
            pooled_e += e;
        } else {
            chi2 += (n as f64 - e).powi(2) / e;
            cells += 1;
        }
    }
    if pooled_e > 0.0 {
        chi2 += (pooled_n - pooled_e).powi(2) / pooled_e;
        cells += 1;
    }
    (chi2, cells - 1)
}

/// The χ² that a correct sampler exceeds with probability about 10⁻⁴ for
/// `dof` degrees of freedom (Wilson–Hilferty, z = 3.72).
pub(crate) fn chi_square_bound(dof: usize) -> f64 {
    let k = dof as f64;
    k * (1.0 - 2.0 / (9.0 * k) + 3.72 * (2.0 / (9.0 * k)).sqrt()).powi(3)
}
