#!/usr/bin/env python3
"""The rough dielectric coat of a plastic (lumen's `plastic`, Mitsuba 3's
`roughplastic`), computed in float64 with numpy: the coat's transmittance
T(mu) and internal reflectance Ri, with either Smith shadowing model, by
either renderer's recipe.

    materials_coat.py [--alpha 0.09] [--eta 1.5] [--albedo 0.6 0.05 0.05]

prints the quantities and what each difference does to the plastic's
diffuse term rho / (1 - rho Ri) T(mu_i) T(mu_o) / (pi eta^2).

The model (both renderers, docs: src/bsdf/plastic.rs, Mitsuba's
roughplastic.cpp and microfacet.h):

  T(mu)  the fraction of light arriving at cosine mu that a single
         scattering off the rough interface (GGX visible normals) refracts
         into the coat: E over visible normals m of (1 - F(wi.m)) G2/G1(wi)
         at the refracted direction;
  R(mu)  the same for reflection (seen from inside: 1/eta);
  Ri     the fraction of the base's diffuse (cosine-distributed) light the
         coat reflects back: integral over mu in [0, 1] of 2 mu R_inside(mu).

G2/G1(wi) is G1(wo) for Mitsuba's separable Smith G1(wi) G1(wo), and
(1 + Lambda_i) / (1 + Lambda_i + Lambda_o) for the height-correlated G of
lumen. Mitsuba tabulates T at 64 values of mu = linspace(0, 1) (Gauss-Legendre
32 x 32 over its visible-normal samples, interpolated linearly) and takes Ri
as 2 * mean over those 64 mu of mu R_inside(mu) (128 x 128 points): the mean
of 64 equally spaced values from 0 to 1 is 63/64 of the trapezoid integral
plus f(1)/128, so its Ri is ~1.5% below the integral. lumen integrates Ri
by the midpoint rule (64 points) over its table of R, tabulated at 32 x 32
(mu, sqrt(alpha)) points and 12 indices from 1 to 3 (1.5 between 1.364 and
1.545), interpolated linearly (src/bsdf/albedo.rs).

Here every integral is a midpoint sum over an N x N grid of the
visible-normal sample square (N = 768 by default; the convergence is
printed), exact up to ~1e-5.
"""

import argparse
import sys

import numpy as np


def ggx_lambda(alpha, w):
    t2 = (w[..., 0] ** 2 + w[..., 1] ** 2) / w[..., 2] ** 2
    return 0.5 * (np.sqrt(1 + alpha * alpha * t2) - 1)


def fresnel_dielectric(cos_i, eta):
    """Unpolarised reflectance at microfacet cosine cos_i >= 0 into relative
    index eta (total internal reflection: 1)."""
    s2t = (1 - cos_i * cos_i) / (eta * eta)
    cos_t = np.sqrt(np.maximum(1 - s2t, 0))
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return np.where(s2t >= 1, 1.0, 0.5 * (rs * rs + rp * rp))


def sample_visible(alpha, wi, u1, u2):
    """GGX visible normals (Heitz 2018) for wi (3,) with wi.z > 0; u1, u2
    arrays. Returns (..., 3)."""
    vh = np.array([alpha * wi[0], alpha * wi[1], wi[2]])
    vh /= np.linalg.norm(vh)
    lensq = vh[0] ** 2 + vh[1] ** 2
    t1 = np.array([-vh[1], vh[0], 0.0]) / np.sqrt(lensq) if lensq > 0 else np.array([1.0, 0, 0])
    t2 = np.cross(vh, t1)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    a, b = r * np.cos(phi), r * np.sin(phi)
    s = 0.5 * (1 + vh[2])
    b = (1 - s) * np.sqrt(np.maximum(1 - a * a, 0)) + s * b
    c = np.sqrt(np.maximum(0, 1 - a * a - b * b))
    nh = a[..., None] * t1 + b[..., None] * t2 + c[..., None] * vh
    ne = np.stack([alpha * nh[..., 0], alpha * nh[..., 1], np.maximum(nh[..., 2], 1e-12)], -1)
    return ne / np.linalg.norm(ne, axis=-1, keepdims=True)


def interface(alpha, eta, mu, smith, n=768):
    """(R, T) of the rough interface seen at cosine mu from the side of
    relative index eta (eta < 1: from inside), single scattering."""
    mu = max(float(mu), 1e-6)
    wi = np.array([np.sqrt(1 - mu * mu), 0.0, mu])
    g = (np.arange(n) + 0.5) / n
    u1, u2 = np.meshgrid(g, g, indexing="ij")
    m = sample_visible(alpha, wi, u1.ravel(), u2.ravel())
    c = m @ wi  # > 0
    f = fresnel_dielectric(c, eta)
    lam_i = ggx_lambda(alpha, wi)

    def g2_over_g1(wo):
        lo = ggx_lambda(alpha, np.stack([wo[:, 0], wo[:, 1], np.abs(wo[:, 2])], -1))
        if smith == "separable":
            return 1 / (1 + lo)
        return (1 + lam_i) / (1 + lam_i + lo)

    wr = 2 * c[:, None] * m - wi
    ok_r = wr[:, 2] > 0
    R = np.where(ok_r, f * g2_over_g1(wr), 0.0).mean()
    # refraction: wt = -wi/eta + m (c/eta - cos_t)
    s2t = (1 - c * c) / (eta * eta)
    ok_t = s2t < 1
    cos_t = np.sqrt(np.maximum(1 - s2t, 0))
    wt = -wi / eta + m * (c / eta - cos_t)[:, None]
    ok_t &= wt[:, 2] < 0
    T = np.where(ok_t, (1 - f) * g2_over_g1(wt), 0.0).mean()
    return R, T


def transmittance(alpha, eta, mus, smith, n=768):
    return np.array([interface(alpha, eta, m, smith, n)[1] for m in mus])


def internal_reflectance(alpha, eta, smith, recipe="exact", n=768):
    """Ri: recipe "exact" (Gauss-Legendre in mu, 48 nodes on each side of the
    total-internal-reflection cusp region split at 0.5 and 0.85) or
    "mitsuba" (2 * mean over mu = linspace(0, 1, 64) of mu R_inside(mu))."""
    if recipe == "mitsuba":
        mus = np.maximum(np.linspace(0, 1, 64), 1e-6)
        return 2 * np.mean([mu * interface(alpha, 1 / eta, mu, smith, n)[0] for mu in mus])
    total = 0.0
    x, w = np.polynomial.legendre.leggauss(48)
    for a, b in ((0.0, 0.5), (0.5, 0.85), (0.85, 1.0)):
        for xi, wi in zip(x, w):
            mu = 0.5 * (b - a) * xi + 0.5 * (a + b)
            total += 0.5 * (b - a) * wi * 2 * mu * interface(alpha, 1 / eta, mu, smith, n)[0]
    return total


def correction(alpha, eta, albedo, n=768, grid=257):
    """What turns Mitsuba's stock roughplastic diffuse term into the
    height-correlated model with the exact Ri: (mus, t_ratio(mu) =
    T_corr(mu) / T_sep(mu), ri_sep_mitsuba, ri_corr_exact). The diffuse term
    is multiplied by t_ratio(mu_i) t_ratio(mu_o) (1 - rho Ri_sep_mitsuba) /
    (1 - rho Ri_corr_exact)."""
    mus = np.linspace(0, 1, grid)
    ts = transmittance(alpha, eta, mus, "separable", n)
    tc = transmittance(alpha, eta, mus, "correlated", n)
    ratio = np.where(ts > 0, tc / np.where(ts > 0, ts, 1), 1.0)
    ri_s = internal_reflectance(alpha, eta, "separable", "mitsuba", n)
    ri_c = internal_reflectance(alpha, eta, "correlated", "exact", n)
    return mus, ratio, ri_s, ri_c


# ------------------------------------- lumen's tables (src/bsdf/albedo.rs)
def _lumen_sample(alpha, wo, u0, u1):
    """lumen's GGX visible normals (Dupuy & Benyoub 2023 spherical caps),
    u0 the azimuth, u1 the cap height, as Microfacet::sample_wm."""
    ws = np.array([alpha * wo[0], alpha * wo[1], wo[2]])
    ws /= np.linalg.norm(ws)
    z = (1 - u1) * (1 + ws[2]) - ws[2]
    st = np.sqrt(np.clip(1 - z * z, 0, 1))
    h = np.stack([st * np.cos(2 * np.pi * u0), st * np.sin(2 * np.pi * u0), z], -1) + ws
    m = np.stack([alpha * h[..., 0], alpha * h[..., 1], np.maximum(h[..., 2], 1e-6)], -1)
    return m / np.linalg.norm(m, axis=-1, keepdims=True)


def _lumen_albedo(alpha, wo, eta, n=32):
    """lumen's dielectric_albedo: (reflected, transmitted) by the midpoint
    rule over an n x n grid (height-correlated G)."""
    g = (np.arange(n) + 0.5) / n
    u1, u0 = np.meshgrid(g, g, indexing="ij")  # u[0] varies fastest
    m = _lumen_sample(alpha, wo, u0.ravel(), u1.ravel())
    c = m @ wo
    f = fresnel_dielectric(np.abs(c), eta)
    lo = ggx_lambda(alpha, wo)

    def w(wi):
        li = ggx_lambda(alpha, np.stack([wi[:, 0], wi[:, 1], np.abs(wi[:, 2])], -1))
        return (1 + lo) / (1 + lo + li)

    ok = c > 0
    wr = 2 * c[:, None] * m - wo
    refl = np.where(ok & (wr[:, 2] > 0), f * w(wr), 0).sum()
    s2t = (1 - c * c) / (eta * eta)
    ct = np.sqrt(np.maximum(1 - s2t, 0))
    wt = -wo / eta + m * (c / eta - ct)[:, None]
    okt = ok & (s2t < 1) & (wt[:, 2] < 0)
    trans = np.where(okt, (1 - f) * w(wt), 0).sum()
    return refl / n / n, trans / n / n


LUMEN_MU = 0.002 + 0.998 * (np.arange(32) / 31) ** 2
LUMEN_R = 0.02 + 0.98 * np.arange(32) / 31
LUMEN_ETA = 1 + 2 * np.arange(12) / 11


def _lumen_lookup(table, r, mu):
    """Bilinear in (sqrt(alpha), mu) over lumen's grid; table[j, i]."""
    fj = np.clip((r - 0.02) / 0.98 * 31, 0, 31)
    t = np.sqrt(np.maximum((mu - 0.002) / 0.998, 0))
    fi = np.clip(t * 31, 0, 31)
    j0, i0 = min(int(fj), 30), np.minimum(fi.astype(int), 30)
    tj, ti = fj - j0, fi - i0
    row = lambda j: table[j, i0] * (1 - ti) + table[j, i0 + 1] * ti  # noqa: E731
    return row(j0) * (1 - tj) + row(j0 + 1) * tj


def lumen_coat(alpha, eta):
    """lumen's coat_transmittance (as a function of mu) and
    coat_internal_reflectance for GGX alpha and index eta, rebuilt from its
    recipe (the two tabulated indices around eta, the two sqrt(alpha) rows
    around sqrt(alpha), linear interpolation)."""
    r = np.sqrt(alpha)
    fk = np.clip((eta - 1) / 2 * 11, 0, 11)
    k0 = min(int(fk), 10)
    tk = fk - k0
    fj = np.clip((r - 0.02) / 0.98 * 31, 0, 31)
    j0 = min(int(fj), 30)
    out, inn = {}, {}
    for k in (k0, k0 + 1):
        e = LUMEN_ETA[k]
        to, ri = np.zeros((32, 32)), np.zeros((32, 32))
        for j in (j0, j0 + 1):
            a = LUMEN_R[j] ** 2
            for i, mu in enumerate(LUMEN_MU):
                wo = np.array([np.sqrt(1 - mu * mu), 0, mu])
                to[j, i] = _lumen_albedo(a, wo, e)[1]
                ri[j, i] = _lumen_albedo(a, wo, 1 / e)[0]
        out[k], inn[k] = to, ri

    def T(mu):
        mu = np.asarray(mu, float)
        v = _lumen_lookup(out[k0], r, mu) * (1 - tk) + _lumen_lookup(out[k0 + 1], r, mu) * tk
        return np.clip(v, 0, 1)

    mus = (np.arange(64) + 0.5) / 64

    def ri_row(k, j):
        return np.mean(2 * mus * _lumen_lookup(inn[k], LUMEN_R[j], mus))

    tj = fj - j0
    ri_k = [ri_row(k, j0) * (1 - tj) + ri_row(k, j0 + 1) * tj for k in (k0, k0 + 1)]
    return T, float(np.clip(ri_k[0] * (1 - tk) + ri_k[1] * tk, 0, 1))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--alpha", type=float, default=0.09)
    ap.add_argument("--eta", type=float, default=1.5)
    ap.add_argument("--albedo", type=float, nargs=3, default=[0.6, 0.05, 0.05])
    ap.add_argument("-n", type=int, default=768, help="quadrature grid per side")
    args = ap.parse_args(argv)
    a, eta, rho = args.alpha, args.eta, np.array(args.albedo)
    print(f"coat: GGX alpha {a}, eta {eta}; base albedo {rho.tolist()}")
    print("convergence of T(0.5), R_inside(0.8), separable: "
          + ", ".join(f"n={n}: {interface(a, eta, 0.5, 'separable', n)[1]:.6f} "
                      f"{interface(a, 1 / eta, 0.8, 'separable', n)[0]:.6f}" for n in (256, 512, 768, 1024)))
    mus = [0.05, 0.2, 0.5, 0.8, 1.0]
    for smith in ("separable", "correlated"):
        t = transmittance(a, eta, mus, smith, args.n)
        print(f"T(mu) {smith:>10}: " + ", ".join(f"{m}: {v:.5f}" for m, v in zip(mus, t)))
    ri = {(s, r): internal_reflectance(a, eta, s, r, args.n)
          for s in ("separable", "correlated") for r in ("exact", "mitsuba")}
    for (s, r), v in ri.items():
        print(f"Ri {s:>10} {r:>7}: {v:.5f}")

    def gain(ri1, ri0):
        return (1 - rho * ri0) / (1 - rho * ri1) - 1

    print("effect on the diffuse term, per channel, of")
    print("  correlated instead of separable G in Ri (exact): "
          + " ".join(f"{100 * x:+.3f}%" for x in gain(ri['correlated', 'exact'], ri['separable', 'exact'])))
    print("  exact Ri instead of Mitsuba's mean (separable):  "
          + " ".join(f"{100 * x:+.3f}%" for x in gain(ri['separable', 'exact'], ri['separable', 'mitsuba'])))
    print("  lumen's model against stock Mitsuba (Ri only):   "
          + " ".join(f"{100 * x:+.3f}%" for x in gain(ri['correlated', 'exact'], ri['separable', 'mitsuba'])))
    lt, lri = lumen_coat(a, eta)
    tc = transmittance(a, eta, mus, "correlated", args.n)
    print(f"lumen's tables: Ri {lri:.5f} (exact correlated {ri['correlated', 'exact']:.5f}); T(mu) "
          + ", ".join(f"{m}: {v:.5f} ({100 * (v / e - 1):+.3f}%)" for m, v, e in zip(mus, lt(mus), tc)))
    print("  lumen's Ri against the exact one, effect on the diffuse term: "
          + " ".join(f"{100 * x:+.3f}%" for x in gain(lri, ri['correlated', 'exact'])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
