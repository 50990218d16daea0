#!/usr/bin/env python3
"""Reproduces the RGB complex indices of refraction in src/material/metals.rs.

Every row of that table is the "CIE colour" of a measured eta(lambda) and
k(lambda) curve, reduced exactly as Mitsuba 3 (3.9.1) reduces the spectra of
its named conductors in its RGB variants (include/mitsuba/render/ior.h
`ior_from_file` -> src/core/spectrum.cpp `spectrum_list_to_srgb(wavelengths,
values, bounded=false, d65=false)`):

  * 1000 uniform steps x_i = 360 + i/999 * (830 - 360) nm; a step outside the
    data's wavelength range is skipped (contributes nothing);
  * the data are interpolated linearly in wavelength;
  * xyz += cie1931_xyz(x_i) * value, where cie1931_xyz linearly interpolates
    the CIE 1931 2-degree table below (360..830 nm in 5 nm steps, float32);
  * xyz *= (830 - 360) / 1000 / 106.7502593994140625 (so that a constant
    spectrum 1 has luminance Y = 1);
  * linear sRGB = M * xyz (Mitsuba's xyz_to_srgb, no gamma), and negative
    components are clamped to 0.

So eta and k are each the colour of their own curve, not a fit to the
reflectance; a renderer that evaluates the Fresnel equations per RGB channel
with them matches Mitsuba's `scalar_rgb` conductors.

Inputs (public, CC0) for the rows Mitsuba lacks:

  refractiveindex.info database, https://github.com/polyanskiy/refractiveindex.info-database
  (commit ff11b589, 2026-06; the same files exist under the older layout
  database/data-nk/<shelf>/<book>/<page>.yml):
    Fe, Ti, Ni  database/data/main/{Fe,Ti,Ni}/nk/Johnson.yml
                P. B. Johnson, R. W. Christy, Phys. Rev. B 9, 5056 (1974)
    Pt          database/data/main/Pt/nk/Rakic-LD.yml
                A. D. Rakic et al., Appl. Opt. 37, 5271 (1998), Lorentz-Drude fit
    CuZn, brass database/data/other/alloys/Cu-Zn/nk/Querry-Cu70Zn30.yml
                M. R. Querry, CRDC-CR-85034 (1985), 70 % Cu / 30 % Zn; this is
                the same curve as pbrt-v4's metal-CuZn-eta/-k
                (mmp/pbrt-v4 src/pbrt/util/spectrum.cpp, CuZn_eta[], CuZn_k[]).

  No zinc: the database's two visible-range Zn curves are not usable.
  Querry 1987 (main/Zn/nk/Querry.yml) gives n = 9..14 across the visible
  (unphysical for a free-electron-like metal); Werner et al. 2009
  (main/Zn/nk/Werner.yml, from electron energy-loss spectra) reduces to
  R0 = (0.89, 0.86, 0.84), but Werner's curves for metals with good optical
  data are far off in the visible (Ti R0 0.97 vs 0.67 from Johnson & Christy,
  Fe 0.91 vs 0.59, W 0.94 vs 0.57 from Mitsuba, and Cu comes out almost
  white: 0.93, 0.88, 0.73 vs 0.95, 0.62, 0.51), so its Zn is not trusted.

  Mitsuba's own rows come from its data/ior/<Name>.{eta,k}.spd files (the
  mitsuba-data submodule; Luxpop / Palik / CXRO-LLNL data, same as pbrt-v3).

How to run (CI has no network, and this script is not run in CI):

  # 1. the rows Mitsuba lacks, from a directory holding the YAML files, either
  #    a checkout of the database (DIR/database/data/...), or the files copied
  #    flat as DIR/<Element>-<page>.yml (Fe-Johnson.yml, Ni-Johnson.yml,
  #    Ti-Johnson.yml, Pt-Rakic-LD.yml, Cu-Zn-Querry-Cu70Zn30.yml):
  python3 scripts/make_metals.py DIR

  # 2. Mitsuba's rows, read back with mi.traverse from the real plugin (and
  #    checked against this script's own reduction of the .spd files):
  /path/to/mitsuba-venv/bin/python scripts/make_metals.py --mitsuba

  # (--mitsuba DIR does both.) Rows go to stdout as Rust `m(name, eta, k,
  # SOURCE)` calls for METALS, SOURCE being one of the citation constants of
  # metals.rs (CITATIONS below); paste them and run rustfmt. Numbers have at
  # least 6 significant digits and at least 6 decimals. Each row follows a
  # comment with its normal-incidence reflectance
  # R0 = ((n-1)^2 + k^2) / ((n+1)^2 + k^2) per channel; notes (data coverage,
  # clamping) go to stderr. Run under the Mitsuba venv, mode 1 also checks
  # the pure-Python reduction against mitsuba.spectrum_list_to_srgb, and mode
  # 2 checks it against every .spd file Mitsuba ships.
"""
import argparse
import bisect
import math
import os
import struct
import sys


def f32(x):
    """Rounds x to the nearest float32 (Mitsuba's tables are float)."""
    return struct.unpack("f", struct.pack("f", x))[0]


CIE_MIN, CIE_MAX, CIE_SAMPLES = 360.0, 830.0, 95
CIE_Y_NORMALIZATION = 1.0 / 106.7502593994140625

# CIE 1931 2-degree colour matching functions, 360..830 nm every 5 nm
# (Mitsuba 3 src/core/spectrum.cpp cie1931_tbl).
# fmt: off
CIE_X = [
    0.000129900000, 0.000232100000, 0.000414900000, 0.000741600000,
    0.001368000000, 0.002236000000, 0.004243000000, 0.007650000000,
    0.014310000000, 0.023190000000, 0.043510000000, 0.077630000000,
    0.134380000000, 0.214770000000, 0.283900000000, 0.328500000000,
    0.348280000000, 0.348060000000, 0.336200000000, 0.318700000000,
    0.290800000000, 0.251100000000, 0.195360000000, 0.142100000000,
    0.095640000000, 0.057950010000, 0.032010000000, 0.014700000000,
    0.004900000000, 0.002400000000, 0.009300000000, 0.029100000000,
    0.063270000000, 0.109600000000, 0.165500000000, 0.225749900000,
    0.290400000000, 0.359700000000, 0.433449900000, 0.512050100000,
    0.594500000000, 0.678400000000, 0.762100000000, 0.842500000000,
    0.916300000000, 0.978600000000, 1.026300000000, 1.056700000000,
    1.062200000000, 1.045600000000, 1.002600000000, 0.938400000000,
    0.854449900000, 0.751400000000, 0.642400000000, 0.541900000000,
    0.447900000000, 0.360800000000, 0.283500000000, 0.218700000000,
    0.164900000000, 0.121200000000, 0.087400000000, 0.063600000000,
    0.046770000000, 0.032900000000, 0.022700000000, 0.015840000000,
    0.011359160000, 0.008110916000, 0.005790346000, 0.004109457000,
    0.002899327000, 0.002049190000, 0.001439971000, 0.000999949300,
    0.000690078600, 0.000476021300, 0.000332301100, 0.000234826100,
    0.000166150500, 0.000117413000, 0.000083075270, 0.000058706520,
    0.000041509940, 0.000029353260, 0.000020673830, 0.000014559770,
    0.000010253980, 0.000007221456, 0.000005085868, 0.000003581652,
    0.000002522525, 0.000001776509, 0.000001251141,
]
CIE_Y = [
    0.000003917000, 0.000006965000, 0.000012390000, 0.000022020000,
    0.000039000000, 0.000064000000, 0.000120000000, 0.000217000000,
    0.000396000000, 0.000640000000, 0.001210000000, 0.002180000000,
    0.004000000000, 0.007300000000, 0.011600000000, 0.016840000000,
    0.023000000000, 0.029800000000, 0.038000000000, 0.048000000000,
    0.060000000000, 0.073900000000, 0.090980000000, 0.112600000000,
    0.139020000000, 0.169300000000, 0.208020000000, 0.258600000000,
    0.323000000000, 0.407300000000, 0.503000000000, 0.608200000000,
    0.710000000000, 0.793200000000, 0.862000000000, 0.914850100000,
    0.954000000000, 0.980300000000, 0.994950100000, 1.000000000000,
    0.995000000000, 0.978600000000, 0.952000000000, 0.915400000000,
    0.870000000000, 0.816300000000, 0.757000000000, 0.694900000000,
    0.631000000000, 0.566800000000, 0.503000000000, 0.441200000000,
    0.381000000000, 0.321000000000, 0.265000000000, 0.217000000000,
    0.175000000000, 0.138200000000, 0.107000000000, 0.081600000000,
    0.061000000000, 0.044580000000, 0.032000000000, 0.023200000000,
    0.017000000000, 0.011920000000, 0.008210000000, 0.005723000000,
    0.004102000000, 0.002929000000, 0.002091000000, 0.001484000000,
    0.001047000000, 0.000740000000, 0.000520000000, 0.000361100000,
    0.000249200000, 0.000171900000, 0.000120000000, 0.000084800000,
    0.000060000000, 0.000042400000, 0.000030000000, 0.000021200000,
    0.000014990000, 0.000010600000, 0.000007465700, 0.000005257800,
    0.000003702900, 0.000002607800, 0.000001836600, 0.000001293400,
    0.000000910930, 0.000000641530, 0.000000451810,
]
CIE_Z = [
    0.000606100000, 0.001086000000, 0.001946000000, 0.003486000000,
    0.006450001000, 0.010549990000, 0.020050010000, 0.036210000000,
    0.067850010000, 0.110200000000, 0.207400000000, 0.371300000000,
    0.645600000000, 1.039050100000, 1.385600000000, 1.622960000000,
    1.747060000000, 1.782600000000, 1.772110000000, 1.744100000000,
    1.669200000000, 1.528100000000, 1.287640000000, 1.041900000000,
    0.812950100000, 0.616200000000, 0.465180000000, 0.353300000000,
    0.272000000000, 0.212300000000, 0.158200000000, 0.111700000000,
    0.078249990000, 0.057250010000, 0.042160000000, 0.029840000000,
    0.020300000000, 0.013400000000, 0.008749999000, 0.005749999000,
    0.003900000000, 0.002749999000, 0.002100000000, 0.001800000000,
    0.001650001000, 0.001400000000, 0.001100000000, 0.001000000000,
    0.000800000000, 0.000600000000, 0.000340000000, 0.000240000000,
    0.000190000000, 0.000100000000, 0.000049999990, 0.000030000000,
    0.000020000000, 0.000010000000,
] + [0.0] * 37
# fmt: on
CIE = [[f32(v) for v in t] for t in (CIE_X, CIE_Y, CIE_Z)]

# Mitsuba's xyz_to_srgb (linear sRGB / Rec. 709 primaries, D65 white).
XYZ_TO_SRGB = [
    [f32(3.240479), f32(-1.537150), f32(-0.498535)],
    [f32(-0.969256), f32(1.875991), f32(0.041556)],
    [f32(0.055648), f32(-0.204043), f32(1.057311)],
]

assert all(len(t) == CIE_SAMPLES for t in CIE)


def cie1931_xyz(x):
    """Mitsuba's cie1931_xyz: the table interpolated linearly, 0 outside."""
    if x < CIE_MIN or x > CIE_MAX:
        return (0.0, 0.0, 0.0)
    t = (x - CIE_MIN) * ((CIE_SAMPLES - 1) / (CIE_MAX - CIE_MIN))
    i0 = min(max(int(t), 0), CIE_SAMPLES - 2)
    w1 = t - i0
    w0 = 1.0 - w1
    return tuple(w0 * c[i0] + w1 * c[i0 + 1] for c in CIE)


def spectrum_list_to_srgb(wavelengths, values):
    """Mitsuba's spectrum_list_to_srgb(..., bounded=false, d65=false).

    Returns (rgb, clamped): clamped says whether a negative channel was set
    to 0 (Mitsuba warns "clamping out-of-gamut color" then).
    """
    steps = 1000
    xyz = [0.0, 0.0, 0.0]
    n = len(wavelengths)
    for i in range(steps):
        x = CIE_MIN + (i / (steps - 1)) * (CIE_MAX - CIE_MIN)
        if x < wavelengths[0] or x > wavelengths[-1]:
            continue
        # math::find_interval: the last index with wavelengths[idx] <= x,
        # clamped to [0, n - 2].
        idx = min(max(bisect.bisect_right(wavelengths, x) - 1, 0), n - 2)
        x0, x1 = wavelengths[idx], wavelengths[idx + 1]
        y0, y1 = values[idx], values[idx + 1]
        y = (x * y0 - x1 * y0 - x * y1 + x0 * y1) / (x0 - x1)
        c = cie1931_xyz(x)
        for j in range(3):
            xyz[j] += c[j] * y
    scale = (CIE_MAX - CIE_MIN) / steps * CIE_Y_NORMALIZATION
    xyz = [v * scale for v in xyz]
    rgb = [sum(XYZ_TO_SRGB[r][j] * xyz[j] for j in range(3)) for r in range(3)]
    clamped = any(v < 0.0 for v in rgb)
    return [max(v, 0.0) for v in rgb], clamped


def coverage(wavelengths):
    """The part of 360..830 nm the data cover, as (lo, hi) in nm."""
    return max(wavelengths[0], CIE_MIN), min(wavelengths[-1], CIE_MAX)


# ---------------------------------------------------------------------------
# Input files


def read_yaml_nk(path):
    """Reads a refractiveindex.info `tabulated nk` YAML file (wavelengths in
    micrometres) as (wavelengths in nm, n, k), sorted by wavelength. Only the
    subset of YAML those files use is understood, so no PyYAML is needed."""
    rows = []
    in_data = False
    kind = None
    with open(path, encoding="utf-8") as f:
        for line in f:
            s = line.strip()
            if s.startswith("- type:"):
                kind = s.split(":", 1)[1].strip()
                if kind != "tabulated nk":
                    raise ValueError(f"{path}: unsupported data type {kind!r}")
                continue
            if s.startswith("data:"):
                in_data = kind == "tabulated nk"
                continue
            if in_data:
                parts = s.split()
                try:
                    row = [float(p) for p in parts]
                except ValueError:
                    row = None
                if row is not None and len(row) == 3:
                    rows.append(row)
                elif s:
                    in_data = False
    if not rows:
        raise ValueError(f"{path}: no tabulated nk data")
    rows.sort()
    wl = [r[0] * 1000.0 for r in rows]
    return wl, [r[1] for r in rows], [r[2] for r in rows]


# The `source` strings of metals.rs, by the name of their constant there.
CITATIONS = {
    "MITSUBA": "Mitsuba 3 (Luxpop/Palik)",
    "JOHNSON_CHRISTY": "Johnson & Christy 1974 via refractiveindex.info",
    "RAKIC": "Rakic et al. 1998 (Lorentz-Drude) via refractiveindex.info",
    "QUERRY_BRASS": "Querry 1985 Cu70Zn30 (= pbrt-v4 metal-CuZn) via refractiveindex.info",
}

# name(s), source (a key of CITATIONS), path of the YAML file in the database
# (new layout, old layout), flat file name.
SOURCES = [
    (
        ["Fe"],
        "JOHNSON_CHRISTY",
        "main/Fe/nk/Johnson.yml",
        "main/Fe/Johnson.yml",
        "Fe-Johnson.yml",
    ),
    (
        ["Ni"],
        "JOHNSON_CHRISTY",
        "main/Ni/nk/Johnson.yml",
        "main/Ni/Johnson.yml",
        "Ni-Johnson.yml",
    ),
    (
        ["Pt"],
        "RAKIC",
        "main/Pt/nk/Rakic-LD.yml",
        "main/Pt/Rakic-LD.yml",
        "Pt-Rakic-LD.yml",
    ),
    (
        ["Ti"],
        "JOHNSON_CHRISTY",
        "main/Ti/nk/Johnson.yml",
        "main/Ti/Johnson.yml",
        "Ti-Johnson.yml",
    ),
    (
        ["CuZn", "brass"],
        "QUERRY_BRASS",
        "other/alloys/Cu-Zn/nk/Querry-Cu70Zn30.yml",
        "other/alloys/Cu-Zn/Querry-Cu70Zn30.yml",
        "Cu-Zn-Querry-Cu70Zn30.yml",
    ),
]


def find_input(root, new, old, flat):
    """The input file under root, in any of the layouts the docstring lists."""
    candidates = [
        os.path.join(root, "database", "data", new),
        os.path.join(root, "data", new),
        os.path.join(root, new),
        os.path.join(root, "database", "data-nk", old),
        os.path.join(root, "data-nk", old),
        os.path.join(root, old),
        os.path.join(root, flat),
    ]
    for c in candidates:
        if os.path.isfile(c):
            return c
    raise FileNotFoundError(f"none of: {', '.join(candidates)}")


# ---------------------------------------------------------------------------
# Output


def lit(x):
    """x as a Rust f32 literal with at least 6 significant digits and at
    least 6 decimals (so values >= 0.1 read as in Mitsuba's printed tables,
    e.g. 1.442045, and small ones keep 6 digits, e.g. 0.000679437)."""
    if x == 0.0:
        return "0.0"
    decimals = max(6, 5 - math.floor(math.log10(abs(x))))
    s = f"{x:.{decimals}f}".rstrip("0")
    return s + "0" if s.endswith(".") else s


def r0(eta, k):
    """Normal-incidence reflectance per channel."""
    return [
        ((n - 1.0) ** 2 + kk * kk) / ((n + 1.0) ** 2 + kk * kk) for n, kk in zip(eta, k)
    ]


def rust_row(name, eta, k, source):
    """A METALS row (source: the name of its citation constant), after a
    comment with its R0."""
    assert source in CITATIONS
    e = ", ".join(lit(v) for v in eta)
    kk = ", ".join(lit(v) for v in k)
    r = ", ".join(f"{v:.4f}" for v in r0(eta, k))
    return (
        f"    // R0 = ({r})\n"
        f'    m("{name}", [{e}], [{kk}], {source}),'
    )


def non_mitsuba_rows(root, mi=None):
    """Reduces the inputs under root; with the mitsuba module, checks the
    reduction against mitsuba.spectrum_list_to_srgb."""
    for names, source, new, old, flat in SOURCES:
        path = find_input(root, new, old, flat)
        wl, n, k = read_yaml_nk(path)
        eta, ce = spectrum_list_to_srgb(wl, n)
        kk, ck = spectrum_list_to_srgb(wl, k)
        lo, hi = coverage(wl)
        inside = sum(1 for w in wl if CIE_MIN <= w <= CIE_MAX)
        note = f"{path}: {inside} samples in 360-830 nm, data cover {lo:.1f}-{hi:.1f} nm"
        if (lo, hi) != (CIE_MIN, CIE_MAX):
            note += "  ** does NOT cover 360-830 nm: the missing steps count as 0 **"
        if ce or ck:
            note += "  ** a negative channel was clamped to 0 **"
        print(f"    // {note}", file=sys.stderr)
        if mi is not None:
            for ours, vals in ((eta, n), (kk, k)):
                theirs = mi.spectrum_list_to_srgb(wl, vals, bounded=False, d65=False)
                err = max(abs(ours[i] - theirs[i]) / max(abs(theirs[i]), 1e-6) for i in range(3))
                if err > 1e-5:
                    raise SystemExit(f"{names[0]}: reduction differs from Mitsuba by {err:g}")
        for name in names:
            print(rust_row(name, eta, kk, source))


def mitsuba_rows():
    """Mitsuba's own rows, read back from its conductor plugin, and checked
    against this script's reduction of the same .spd files."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    mi.set_log_level(mi.LogLevel.Error)
    d = os.path.join(os.path.dirname(mi.__file__), "data", "ior")
    names = sorted({f.rsplit(".", 2)[0] for f in os.listdir(d) if f.endswith(".spd")})
    print(f"    // Mitsuba {mi.__version__}, {len(names)} names", file=sys.stderr)
    for name in names:
        p = mi.traverse(mi.load_dict({"type": "conductor", "material": name}))
        eta = [float(v) for v in p["eta.value"]]
        k = [float(v) for v in p["k.value"]]
        for part, theirs in (("eta", eta), ("k", k)):
            wl, vals = mi.spectrum_from_file(os.path.join(d, f"{name}.{part}.spd"))
            wl, vals = list(wl), list(vals)
            ours, clamped = spectrum_list_to_srgb(wl, vals)
            lo, hi = coverage(wl)
            if (lo, hi) != (CIE_MIN, CIE_MAX):
                print(
                    f"    // {name}.{part}: data cover only {lo:.1f}-{hi:.1f} nm"
                    " (Mitsuba counts the missing steps as 0)",
                    file=sys.stderr,
                )
            if clamped:
                print(f"    // {name}.{part}: a negative channel was clamped to 0", file=sys.stderr)
            err = max(abs(ours[i] - theirs[i]) for i in range(3))
            if err > 1e-5 * max(1.0, max(theirs)):
                print(f"    // {name}.{part}: pure-Python reduction differs by {err:g}", file=sys.stderr)
        print(rust_row(name, eta, k, "MITSUBA"))
    return mi


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("data_dir", nargs="?", help="directory of refractiveindex.info YAML files")
    ap.add_argument("--mitsuba", action="store_true", help="print Mitsuba's rows (needs its venv)")
    args = ap.parse_args()
    if not args.data_dir and not args.mitsuba:
        ap.error("give a data directory, --mitsuba, or both")
    mi = None
    if args.mitsuba:
        mi = mitsuba_rows()
    else:
        try:
            import mitsuba as mi

            mi.set_variant("scalar_rgb")
            mi.set_log_level(mi.LogLevel.Error)
        except ImportError:
            mi = None
    if args.data_dir:
        non_mitsuba_rows(args.data_dir, mi)


if __name__ == "__main__":
    main()
