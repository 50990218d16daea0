//! Named conductors (`metal = "Au"` on a `conductor` material) as RGB complex
//! indices of refraction, and named dielectric indices of refraction.
//!
//! # The reduction
//!
//! Every entry of [`METALS`] is a measured spectral index η(λ) + i·k(λ)
//! reduced to linear sRGB exactly as Mitsuba 3 does it in its RGB variants
//! (`ior_from_file` → `spectrum_list_to_srgb(λ, values, bounded = false)`):
//! η and k are each reduced on their own, as the "CIE colour" of the curve,
//!
//! - at 1000 uniform wavelengths λᵢ = 360 + i/999 · (830 − 360) nm, the curve
//!   interpolated linearly (a λᵢ outside the data is skipped, i.e. counts
//!   as 0),
//! - XYZ = Σ x̄ȳz̄(λᵢ) · v(λᵢ) · (470 nm / 1000) / 106.7502593994140625 (the
//!   CIE 1931 2° table at 5 nm, interpolated linearly; the factor makes a
//!   constant curve v = 1 luminance 1),
//! - RGB = M · XYZ with the linear sRGB (Rec. 709, D65) matrix
//!   [[3.240479, −1.537150, −0.498535], [−0.969256, 1.875991, 0.041556],
//!   [0.055648, −0.204043, 1.057311]], negative channels set to 0.
//!
//! So the values are not fitted to a reflectance: the Fresnel equations
//! evaluated per channel with them give what Mitsuba 3's `scalar_rgb`
//! `conductor` and `roughconductor` give. The normal-incidence reflectance
//! R₀ = ((η − 1)² + k²) / ((η + 1)² + k²) of each channel is noted above its
//! row.
//!
//! # Sources
//!
//! - Every name Mitsuba 3 accepts for a conductor (its `data/ior/*.spd`
//!   files, 71 names; `none`, its perfect mirror η = 0, k = 1, is not a
//!   metal and is left out), with the values Mitsuba 3.9.1 itself uses, read
//!   back with `mi.traverse` and kept to at least 6 significant digits. The
//!   data are the Luxpop database's (as in pbrt-v3), after Palik's
//!   *Handbook of Optical Constants of Solids* and CXRO/LLNL; `X` and
//!   `X_palik` are mostly the same curve, but `Cu` and `Cu_palik` differ.
//!   Some of those curves stop short of 830 nm, and the missing steps count
//!   as 0, so their values (the red channel above all) come out too low;
//!   they are kept as Mitsuba has them:
//!   `AlSb` (data end at 590 nm: its red η and k are 0), `d-C` (656 nm),
//!   `Se`, `Se-e` (689 nm), `Li` (751 nm), `MgO` (768 nm), `ThF4`
//!   (800 nm). A few transparent crystals had tiny negative k clamped to 0.
//! - Metals Mitsuba lacks, from the refractiveindex.info database
//!   (`polyanskiy/refractiveindex.info-database`, CC0), every curve covering
//!   the whole of 360–830 nm:
//!   - `Fe`, `Ni`, `Ti`: P. B. Johnson and R. W. Christy, Phys. Rev. B 9,
//!     5056 (1974) (this `Ni` is a little brighter than Mitsuba's
//!     `Ni_palik`: R₀ 0.73, 0.63, 0.53 against 0.70, 0.59, 0.49);
//!   - `Pt`: A. D. Rakić et al., Appl. Opt. 37, 5271 (1998), Lorentz–Drude
//!     fit;
//!   - `CuZn` and `brass` (the same values): M. R. Querry, CRDC-CR-85034
//!     (1985), 70 % Cu and 30 % Zn, the curve of pbrt-v4's `metal-CuZn`.
//!
//!   There is no zinc: the database's visible-range zinc data are not
//!   trustworthy (Querry's has n ≈ 9–14; Werner et al. 2009's, from
//!   electron energy-loss spectra, is far too bright for the metals it
//!   shares with better data).
//!
//! `scripts/make_metals.py` reproduces the added rows from those files, and
//! Mitsuba's rows from its Python package.
//!
//! [`IORS`] is Mitsuba 3's table of named dielectrics (`ior.h`, values
//! mostly from Hecht, *Optics*, 4th ed., at about 589 nm and 0–20 °C).

/// A conductor's complex index of refraction, reduced to RGB.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NamedMetal {
    /// The name a scene gives it (`metal = "Au"`); matched exactly.
    pub name: &'static str,
    /// Real part η of the index of refraction, linear sRGB (R, G, B).
    pub eta: [f32; 3],
    /// Imaginary part k (the extinction coefficient), linear sRGB (R, G, B).
    pub k: [f32; 3],
    /// Where the spectral data come from, as a short citation.
    pub source: &'static str,
}

/// Mitsuba 3's own data.
const MITSUBA: &str = "Mitsuba 3 (Luxpop/Palik)";
/// Johnson and Christy's transition metals.
const JOHNSON_CHRISTY: &str = "Johnson & Christy 1974 via refractiveindex.info";
/// Rakić et al.'s fits.
const RAKIC: &str = "Rakic et al. 1998 (Lorentz-Drude) via refractiveindex.info";
/// Querry's brass, as in pbrt-v4.
const QUERRY_BRASS: &str = "Querry 1985 Cu70Zn30 (= pbrt-v4 metal-CuZn) via refractiveindex.info";

/// A row of [`METALS`].
const fn m(name: &'static str, eta: [f32; 3], k: [f32; 3], source: &'static str) -> NamedMetal {
    NamedMetal {
        name,
        eta,
        k,
        source,
    }
}

/// Every named conductor: Mitsuba 3's, then the ones lumen adds. Each name
/// appears once.
pub const METALS: &[NamedMetal] = &[
    // Mitsuba 3.9.1, `scalar_rgb`: every name it accepts (its data/ior/*.spd
    // files), in its order.
    // R0 = (0.9748, 0.9575, 0.9063)
    m(
        "Ag",
        [0.155276, 0.116728, 0.138388],
        [4.828354, 3.122222, 2.146901],
        MITSUBA,
    ),
    // R0 = (0.9280, 0.9178, 0.9189)
    m(
        "Al",
        [1.657501, 0.880405, 0.521244],
        [9.223811, 6.269502, 4.837004],
        MITSUBA,
    ),
    // R0 = (0.3200, 0.2783, 0.1430)
    m(
        "AlAs",
        [3.605296, 3.232938, 2.216319],
        [0.000679437, 0.0, 0.00751271],
        MITSUBA,
    ),
    // R0 = (0.3200, 0.2783, 0.1430)
    m(
        "AlAs_palik",
        [3.605296, 3.232938, 2.216319],
        [0.000679437, 0.0, 0.00751271],
        MITSUBA,
    ),
    // R0 = (1.0000, 0.3733, 0.4479)
    m(
        "AlSb",
        [0.0, 4.139375, 4.669254],
        [0.0, 0.0940091, 1.30057],
        MITSUBA,
    ),
    // R0 = (1.0000, 0.3733, 0.4479)
    m(
        "AlSb_palik",
        [0.0, 4.139375, 4.669254],
        [0.0, 0.0940091, 1.30057],
        MITSUBA,
    ),
    // R0 = (0.9667, 0.8020, 0.3241)
    m(
        "Au",
        [0.143036, 0.375307, 1.442045],
        [3.982997, 2.385556, 1.603359],
        MITSUBA,
    ),
    // R0 = (0.5975, 0.5206, 0.5062)
    m(
        "Be",
        [4.185012, 3.185029, 2.784061],
        [3.835466, 3.010122, 2.868994],
        MITSUBA,
    ),
    // R0 = (0.5975, 0.5206, 0.5062)
    m(
        "Be_palik",
        [4.185012, 3.185029, 2.784061],
        [3.835466, 3.010122, 2.868994],
        MITSUBA,
    ),
    // R0 = (0.6876, 0.6491, 0.6870)
    m(
        "Cr",
        [4.369668, 2.916505, 1.654905],
        [5.206547, 4.231306, 3.754699],
        MITSUBA,
    ),
    // R0 = (0.1325, 0.0675, 0.0619)
    m(
        "CsI",
        [2.1449, 1.702319, 1.662427],
        [0.0, 0.0, 0.0],
        MITSUBA,
    ),
    // R0 = (0.1325, 0.0675, 0.0619)
    m(
        "CsI_palik",
        [2.1449, 1.702319, 1.662427],
        [0.0, 0.0, 0.0],
        MITSUBA,
    ),
    // R0 = (0.9520, 0.6198, 0.5106)
    m(
        "Cu",
        [0.201005, 0.92375, 1.102215],
        [3.913262, 2.453045, 2.14209],
        MITSUBA,
    ),
    // R0 = (0.3147, 0.2455, 0.2379)
    m(
        "Cu2O",
        [3.551773, 2.94987, 2.751875],
        [0.114207, 0.193897, 0.606134],
        MITSUBA,
    ),
    // R0 = (0.3147, 0.2455, 0.2379)
    m(
        "Cu2O_palik",
        [3.551773, 2.94987, 2.751875],
        [0.114207, 0.193897, 0.606134],
        MITSUBA,
    ),
    // R0 = (0.2907, 0.1982, 0.1834)
    m(
        "CuO",
        [3.247541, 2.447805, 2.21022],
        [0.52109, 0.570031, 0.722179],
        MITSUBA,
    ),
    // R0 = (0.2907, 0.1982, 0.1834)
    m(
        "CuO_palik",
        [3.247541, 2.447805, 2.21022],
        [0.52109, 0.570031, 0.722179],
        MITSUBA,
    ),
    // R0 = (0.9494, 0.6217, 0.5092)
    m(
        "Cu_palik",
        [0.213229, 0.919715, 1.102411],
        [3.921873, 2.457332, 2.136584],
        MITSUBA,
    ),
    // R0 = (0.8140, 0.7702, 0.7631)
    m(
        "Hg",
        [2.398939, 1.440028, 0.90957],
        [6.327587, 4.371925, 3.421764],
        MITSUBA,
    ),
    // R0 = (0.4699, 0.3665, 0.3507)
    m(
        "HgTe",
        [4.77904, 3.231196, 2.659901],
        [1.631613, 1.58081, 1.729287],
        MITSUBA,
    ),
    // R0 = (0.4699, 0.3665, 0.3507)
    m(
        "HgTe_palik",
        [4.77904, 3.231196, 2.659901],
        [1.631613, 1.58081, 1.729287],
        MITSUBA,
    ),
    // R0 = (0.8140, 0.7702, 0.7631)
    m(
        "Hg_palik",
        [2.398939, 1.440028, 0.90957],
        [6.327587, 4.371925, 3.421764],
        MITSUBA,
    ),
    // R0 = (0.7426, 0.6802, 0.6308)
    m(
        "Ir",
        [3.0863, 2.082191, 1.617915],
        [5.592153, 4.067088, 3.267312],
        MITSUBA,
    ),
    // R0 = (0.7426, 0.6802, 0.6308)
    m(
        "Ir_palik",
        [3.0863, 2.082191, 1.617915],
        [5.592153, 4.067088, 3.267312],
        MITSUBA,
    ),
    // R0 = (0.9539, 0.9363, 0.9201)
    m(
        "K",
        [0.0640432, 0.0464098, 0.0381849],
        [2.1042, 1.34894, 0.913126],
        MITSUBA,
    ),
    // R0 = (0.9539, 0.9363, 0.9201)
    m(
        "K_palik",
        [0.0640432, 0.0464098, 0.0381849],
        [2.1042, 1.34894, 0.913126],
        MITSUBA,
    ),
    // R0 = (0.9248, 0.8844, 0.7933)
    m(
        "Li",
        [0.265791, 0.195618, 0.220949],
        [3.540155, 2.311123, 1.668607],
        MITSUBA,
    ),
    // R0 = (0.9248, 0.8844, 0.7933)
    m(
        "Li_palik",
        [0.265791, 0.195618, 0.220949],
        [3.540155, 2.311123, 1.668607],
        MITSUBA,
    ),
    // R0 = (0.1244, 0.0603, 0.0526)
    m(
        "MgO",
        [2.089584, 1.650723, 1.594879],
        [0.0000000000043327, 0.0, 0.0000000000249865],
        MITSUBA,
    ),
    // R0 = (0.1244, 0.0603, 0.0526)
    m(
        "MgO_palik",
        [2.089584, 1.650723, 1.594879],
        [0.0000000000043327, 0.0, 0.0000000000249865],
        MITSUBA,
    ),
    // R0 = (0.6182, 0.5618, 0.5409)
    m(
        "Mo",
        [4.483974, 3.525131, 2.77631],
        [4.111437, 3.420827, 3.150607],
        MITSUBA,
    ),
    // R0 = (0.6182, 0.5618, 0.5409)
    m(
        "Mo_palik",
        [4.483974, 3.525131, 2.77631],
        [4.111437, 3.420827, 3.150607],
        MITSUBA,
    ),
    // R0 = (0.9785, 0.9597, 0.9315)
    m(
        "Na_palik",
        [0.0602694, 0.0561409, 0.0619884],
        [3.179273, 2.11249, 1.579041],
        MITSUBA,
    ),
    // R0 = (0.5640, 0.4895, 0.4731)
    m(
        "Nb",
        [3.420074, 2.790093, 2.395629],
        [3.441395, 2.737666, 2.579746],
        MITSUBA,
    ),
    // R0 = (0.5640, 0.4895, 0.4731)
    m(
        "Nb_palik",
        [3.420074, 2.790093, 2.395629],
        [3.441395, 2.737666, 2.579746],
        MITSUBA,
    ),
    // R0 = (0.7001, 0.5942, 0.4936)
    m(
        "Ni_palik",
        [2.367305, 1.663373, 1.467078],
        [4.498812, 3.050153, 2.345439],
        MITSUBA,
    ),
    // R0 = (0.8243, 0.7544, 0.7216)
    m(
        "Rh",
        [2.585793, 1.860216, 1.554263],
        [6.78226, 4.702987, 3.976073],
        MITSUBA,
    ),
    // R0 = (0.8243, 0.7544, 0.7216)
    m(
        "Rh_palik",
        [2.585793, 1.860216, 1.554263],
        [6.78226, 4.702987, 3.976073],
        MITSUBA,
    ),
    // R0 = (0.3793, 0.2507, 0.2413)
    m(
        "Se",
        [4.058311, 2.842935, 2.820853],
        [0.75405, 0.638444, 0.521808],
        MITSUBA,
    ),
    // R0 = (0.5019, 0.4029, 0.4225)
    m(
        "Se-e",
        [5.722849, 4.165736, 4.081338],
        [0.871136, 1.105157, 1.56532],
        MITSUBA,
    ),
    // R0 = (0.5019, 0.4029, 0.4225)
    m(
        "Se-e_palik",
        [5.722849, 4.165736, 4.081338],
        [0.871136, 1.105157, 1.56532],
        MITSUBA,
    ),
    // R0 = (0.3793, 0.2507, 0.2413)
    m(
        "Se_palik",
        [4.058311, 2.842935, 2.820853],
        [0.75405, 0.638444, 0.521808],
        MITSUBA,
    ),
    // R0 = (0.2711, 0.1873, 0.1808)
    m(
        "SiC",
        [3.172342, 2.525972, 2.479371],
        [0.000000753766, 0.0, 0.0000101925],
        MITSUBA,
    ),
    // R0 = (0.2711, 0.1873, 0.1808)
    m(
        "SiC_palik",
        [3.172342, 2.525972, 2.479371],
        [0.000000753766, 0.0, 0.0000101925],
        MITSUBA,
    ),
    // R0 = (0.4070, 0.1084, 0.0152)
    m(
        "SnTe",
        [4.52425, 1.981645, 1.281591],
        [0.0, 0.0, 0.0],
        MITSUBA,
    ),
    // R0 = (0.4070, 0.1084, 0.0152)
    m(
        "SnTe_palik",
        [4.52425, 1.981645, 1.281591],
        [0.0, 0.0, 0.0],
        MITSUBA,
    ),
    // R0 = (0.4565, 0.3419, 0.3799)
    m(
        "Ta",
        [2.062721, 2.392939, 2.627929],
        [2.40836, 1.741486, 1.947028],
        MITSUBA,
    ),
    // R0 = (0.4565, 0.3419, 0.3799)
    m(
        "Ta_palik",
        [2.062721, 2.392939, 2.627929],
        [2.40836, 1.741486, 1.947028],
        MITSUBA,
    ),
    // R0 = (0.6350, 0.5781, 0.5617)
    m(
        "Te",
        [7.390234, 4.482105, 2.637106],
        [3.256022, 3.527059, 3.292054],
        MITSUBA,
    ),
    // R0 = (0.7100, 0.6728, 0.6532)
    m(
        "Te-e",
        [7.508907, 4.296429, 2.369988],
        [5.583929, 4.947205, 3.997592],
        MITSUBA,
    ),
    // R0 = (0.7100, 0.6728, 0.6532)
    m(
        "Te-e_palik",
        [7.508907, 4.296429, 2.369988],
        [5.583929, 4.947205, 3.997592],
        MITSUBA,
    ),
    // R0 = (0.6350, 0.5781, 0.5617)
    m(
        "Te_palik",
        [7.390234, 4.482105, 2.637106],
        [3.256022, 3.527059, 3.292054],
        MITSUBA,
    ),
    // R0 = (0.0861, 0.0328, 0.0264)
    m(
        "ThF4",
        [1.830714, 1.442229, 1.387648],
        [0.0, 0.0, 0.0],
        MITSUBA,
    ),
    // R0 = (0.0861, 0.0328, 0.0264)
    m(
        "ThF4_palik",
        [1.830714, 1.442229, 1.387648],
        [0.0, 0.0, 0.0],
        MITSUBA,
    ),
    // R0 = (0.5482, 0.4397, 0.4116)
    m(
        "TiC",
        [3.700528, 2.837422, 2.582287],
        [3.265635, 2.351589, 2.172791],
        MITSUBA,
    ),
    // R0 = (0.5482, 0.4397, 0.4116)
    m(
        "TiC_palik",
        [3.700528, 2.837422, 2.582287],
        [3.265635, 2.351589, 2.172791],
        MITSUBA,
    ),
    // R0 = (0.6409, 0.4523, 0.1976)
    m(
        "TiN",
        [1.64845, 1.150516, 1.379823],
        [3.368328, 1.943498, 1.102068],
        MITSUBA,
    ),
    // R0 = (0.6409, 0.4523, 0.1976)
    m(
        "TiN_palik",
        [1.64845, 1.150516, 1.379823],
        [3.368328, 1.943498, 1.102068],
        MITSUBA,
    ),
    // R0 = (0.3039, 0.2246, 0.2380)
    m(
        "TiO2",
        [3.45661, 2.801736, 2.905175],
        [0.000105265, 0.0, 0.000652887],
        MITSUBA,
    ),
    // R0 = (0.2631, 0.1855, 0.1951)
    m(
        "TiO2-e",
        [3.106565, 2.513168, 2.582444],
        [0.0000297516, 0.0, 0.000182698],
        MITSUBA,
    ),
    // R0 = (0.2631, 0.1855, 0.1951)
    m(
        "TiO2-e_palik",
        [3.106565, 2.513168, 2.582444],
        [0.0000297516, 0.0, 0.000182698],
        MITSUBA,
    ),
    // R0 = (0.3039, 0.2246, 0.2380)
    m(
        "TiO2_palik",
        [3.45661, 2.801736, 2.905175],
        [0.000105265, 0.0, 0.000652887],
        MITSUBA,
    ),
    // R0 = (0.5297, 0.4179, 0.3798)
    m(
        "VC",
        [3.657566, 2.752736, 2.532672],
        [3.068301, 2.198687, 1.963193],
        MITSUBA,
    ),
    // R0 = (0.5297, 0.4179, 0.3798)
    m(
        "VC_palik",
        [3.657566, 2.752736, 2.532672],
        [3.068301, 2.198687, 1.963193],
        MITSUBA,
    ),
    // R0 = (0.5251, 0.3926, 0.3106)
    m(
        "VN",
        [2.865602, 2.119189, 1.940091],
        [3.032243, 2.056116, 1.616306],
        MITSUBA,
    ),
    // R0 = (0.5251, 0.3926, 0.3106)
    m(
        "VN_palik",
        [2.865602, 2.119189, 1.940091],
        [3.032243, 2.056116, 1.616306],
        MITSUBA,
    ),
    // R0 = (0.5727, 0.5107, 0.5365)
    m(
        "V_palik",
        [4.277582, 3.512949, 2.761071],
        [3.491301, 2.889455, 3.111522],
        MITSUBA,
    ),
    // R0 = (0.5746, 0.4778, 0.4331)
    m(
        "W",
        [4.370817, 3.300246, 2.998407],
        [3.500641, 2.604874, 2.273233],
        MITSUBA,
    ),
    // R0 = (0.2794, 0.1940, 0.1691)
    m(
        "a-C",
        [2.944046, 2.227136, 1.968162],
        [0.887465, 0.799299, 0.81529],
        MITSUBA,
    ),
    // R0 = (0.2123, 0.1579, 0.1449)
    m(
        "d-C",
        [2.70872, 2.318826, 2.228898],
        [0.0, 0.0, 0.0],
        MITSUBA,
    ),
    // R0 = (0.2123, 0.1579, 0.1449)
    m(
        "d-C_palik",
        [2.70872, 2.318826, 2.228898],
        [0.0, 0.0, 0.0],
        MITSUBA,
    ),
    // Not in Mitsuba: the same reduction applied to published measurements
    // (scripts/make_metals.py).
    // R0 = (0.5869, 0.4958, 0.4621)
    m(
        "Fe",
        [3.514478, 2.769762, 2.301729],
        [3.695026, 2.786126, 2.492985],
        JOHNSON_CHRISTY,
    ),
    // R0 = (0.7341, 0.6264, 0.5315)
    m(
        "Ni",
        [2.423165, 1.80444, 1.563506],
        [4.972949, 3.384562, 2.603284],
        JOHNSON_CHRISTY,
    ),
    // R0 = (0.7186, 0.6236, 0.5538)
    m(
        "Pt",
        [2.796112, 1.967285, 1.654495],
        [5.033536, 3.478602, 2.790218],
        RAKIC,
    ),
    // R0 = (0.6657, 0.5638, 0.5118)
    m(
        "Ti",
        [3.275403, 2.379756, 2.024694],
        [4.57234, 3.224525, 2.727811],
        JOHNSON_CHRISTY,
    ),
    // R0 = (0.9013, 0.7756, 0.3784)
    m(
        "CuZn",
        [0.519744, 0.488639, 1.04196],
        [4.330531, 2.548065, 1.592235],
        QUERRY_BRASS,
    ),
    // R0 = (0.9013, 0.7756, 0.3784)
    m(
        "brass",
        [0.519744, 0.488639, 1.04196],
        [4.330531, 2.548065, 1.592235],
        QUERRY_BRASS,
    ),
];

/// The conductor called exactly `name` (case matters: `"Au"`, `"Cu_palik"`,
/// `"brass"`).
pub fn find(name: &str) -> Option<&'static NamedMetal> {
    METALS.iter().find(|m| m.name == name)
}

/// The names of all the conductors, in the order of [`METALS`].
pub fn names() -> impl Iterator<Item = &'static str> {
    METALS.iter().map(|m| m.name)
}

/// Named dielectric indices of refraction (Mitsuba's table, Hecht's Optics): name, ior
pub const IORS: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// The index of refraction of the dielectric called `name`, ignoring ASCII
/// case as Mitsuba does (`"BK7"`, `"Water Ice"`).
pub fn find_ior(name: &str) -> Option<f32> {
    IORS.iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|&(_, ior)| ior)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    /// Normal-incidence reflectance per channel.
    fn r0(m: &NamedMetal) -> [f32; 3] {
        std::array::from_fn(|i| {
            let (n, k) = (m.eta[i], m.k[i]);
            ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
        })
    }

    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-6 * y.abs().max(1.0))
    }

    #[test]
    fn every_name_is_unique() {
        let mut seen = HashSet::new();
        for name in names() {
            assert!(seen.insert(name), "{name} appears twice");
        }
        assert_eq!(seen.len(), METALS.len());
        let mut seen = HashSet::new();
        for (name, _) in IORS {
            assert!(
                seen.insert(name.to_ascii_lowercase()),
                "{name} appears twice"
            );
        }
    }

    #[test]
    fn values_are_finite_and_non_negative() {
        for m in METALS {
            for v in m.eta.iter().chain(&m.k) {
                assert!(v.is_finite() && *v >= 0.0, "{}: {v}", m.name);
            }
            assert!(!m.source.is_empty(), "{} has no source", m.name);
        }
        for (name, ior) in IORS {
            assert!(ior.is_finite() && *ior >= 1.0, "{name}: {ior}");
        }
    }

    #[test]
    fn gold_is_mitsubas() {
        let au = find("Au").unwrap();
        assert!(close(au.eta, [0.143036, 0.375307, 1.442045]), "{au:?}");
        assert!(close(au.k, [3.982997, 2.385556, 1.603359]), "{au:?}");
        assert_eq!(au.source, MITSUBA);
    }

    #[test]
    fn gold_is_reddish_and_silver_and_aluminium_are_bright() {
        let [r, g, b] = r0(find("Au").unwrap());
        assert!(r > g && g > b, "Au R0 = {r}, {g}, {b}");
        for name in ["Ag", "Al"] {
            let r = r0(find(name).unwrap());
            assert!(r.iter().all(|&c| c > 0.9), "{name} R0 = {r:?}");
        }
    }

    #[test]
    fn every_mitsuba_name_is_there_and_none_is_not() {
        assert_eq!(METALS.iter().filter(|m| m.source == MITSUBA).count(), 71);
        for name in [
            "Au",
            "Ag",
            "Cu",
            "Cu_palik",
            "Al",
            "Cr",
            "Ni_palik",
            "W",
            "a-C",
            "d-C_palik",
        ] {
            assert_eq!(find(name).map(|m| m.source), Some(MITSUBA), "{name}");
        }
        assert!(find("none").is_none());
        // Cu and Cu_palik are different curves.
        assert_ne!(find("Cu").unwrap().eta, find("Cu_palik").unwrap().eta);
        // The notes' table (`scalar_rgb`, `mi.traverse`).
        let cr = find("Cr").unwrap();
        assert!(close(cr.eta, [4.369668, 2.916505, 1.654905]), "{cr:?}");
        assert!(close(cr.k, [5.206547, 4.231306, 3.754699]), "{cr:?}");
    }

    #[test]
    fn lumens_additions_are_there() {
        for name in ["Fe", "Ti", "Pt", "Ni", "CuZn", "brass"] {
            let m = find(name).unwrap_or_else(|| panic!("no {name}"));
            assert_ne!(m.source, MITSUBA, "{name}");
            let r = r0(m);
            assert!(r.iter().all(|&c| c > 0.3 && c < 1.0), "{name} R0 = {r:?}");
        }
        assert_eq!(find("CuZn").unwrap().eta, find("brass").unwrap().eta);
        // Brass is yellow: red above green above blue, blue well below.
        let [r, g, b] = r0(find("brass").unwrap());
        assert!(r > g && g > b && b < 0.5, "brass R0 = {r}, {g}, {b}");
    }

    #[test]
    fn find_is_exact() {
        assert!(find("au").is_none());
        assert!(find("AU").is_none());
        assert!(find(" Au").is_none());
        assert!(find("").is_none());
        assert_eq!(find("Cu_palik").unwrap().name, "Cu_palik");
        assert_eq!(names().count(), METALS.len());
        assert_eq!(names().next(), Some(METALS[0].name));
    }

    #[test]
    fn iors_are_mitsubas_and_case_insensitive() {
        assert_eq!(find_ior("BK7"), Some(1.5046));
        assert_eq!(find_ior("bk7"), Some(1.5046));
        assert_eq!(find_ior("Water Ice"), Some(1.31));
        assert_eq!(find_ior("AIR"), Some(1.000277));
        assert_eq!(find_ior("diamond"), Some(2.419));
        assert_eq!(find_ior("glass"), None);
        assert_eq!(find_ior("water ice "), None);
        assert_eq!(IORS.len(), 23);
    }
}
