//! The output transform (gamma, clamping, 8-bit quantisation) and the image
//! encoders, checked value by value.

mod common;

use lumen::film::{to_display, Film, Sum};
use lumen::output::{encode_pfm, encode_ppm, write_image, ImageFormat};
use lumen::scene::desc::BackgroundDesc;
use lumen::scene::Scene;
use std::path::{Path, PathBuf};

fn scratch_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("output-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A film whose pixels are exactly the given linear colours (one sample each,
/// except pixels given as `None`, which have no sample).
fn film_of(width: u32, height: u32, pixels: &[Option<[f64; 3]>]) -> Film {
    let sums = pixels
        .iter()
        .map(|p| Sum::of(p.unwrap_or([0.0; 3])).unwrap())
        .collect();
    let counts = pixels.iter().map(|p| u32::from(p.is_some())).collect();
    Film::from_raw(width, height, sums, counts).unwrap()
}

#[test]
fn gamma_two_takes_the_square_root() {
    assert!((to_display(0.25, 2.0) - 0.5).abs() <= f32::EPSILON);
    for i in 0..=100 {
        let v = i as f32 / 100.0;
        assert!((to_display(v, 2.0) - v.sqrt()).abs() <= 2.0 * f32::EPSILON);
        assert!((to_display(v, 2.2) - v.powf(1.0 / 2.2)).abs() <= 2.0 * f32::EPSILON);
    }
}

#[test]
fn gamma_one_is_the_identity_on_the_unit_interval() {
    for i in 0..=1000 {
        let v = i as f32 / 1000.0;
        assert_eq!(to_display(v, 1.0), v);
    }
}

#[test]
fn display_values_are_clamped_to_the_unit_interval() {
    for gamma in [1.0, 2.0, 0.5] {
        assert_eq!(to_display(4.0, gamma), 1.0);
        assert_eq!(to_display(1e30, gamma), 1.0);
        assert_eq!(to_display(-0.5, gamma), 0.0);
        assert_eq!(to_display(0.0, gamma), 0.0);
        assert_eq!(to_display(1.0, gamma), 1.0);
    }
}

#[test]
fn eight_bit_values_are_floor_of_256_times_the_clamped_value() {
    // Values k/1024 are exact in f32, so the reference in f64 is exact too.
    let values: Vec<f64> = (-64..=1280).map(|k| f64::from(k) / 1024.0).collect();
    let pixels: Vec<Option<[f64; 3]>> = values.iter().map(|&v| Some([v, v, v])).collect();
    let film = film_of(values.len() as u32, 1, &pixels);
    let bytes = film.to_rgb8(1.0);
    let top = f64::from(0.999f32);
    for (i, &v) in values.iter().enumerate() {
        let expected = (256.0 * v.clamp(0.0, top)).floor() as u8;
        assert_eq!(bytes[3 * i], expected, "v = {v}");
    }
    assert_eq!(
        bytes[3 * values.iter().position(|&v| v == 0.5).unwrap()],
        128
    );
    assert_eq!(*bytes.last().unwrap(), 255);
    // With gamma 2 the transform comes first: 0.25 → 0.5 → 128.
    assert_eq!(
        film_of(1, 1, &[Some([0.25, 1.0, 0.0])]).to_rgb8(2.0),
        [128, 255, 0]
    );
}

#[test]
fn a_pixel_without_samples_is_black_and_means_divide_by_the_count() {
    let sums = vec![Sum::ZERO, Sum::of([3.0, 1.5, 0.75]).unwrap()];
    let film = Film::from_raw(2, 1, sums, vec![0, 3]).unwrap();
    assert_eq!(film.pixel(0, 0), lumen::math::Color::ZERO);
    assert_eq!(film.pixel(1, 0), lumen::math::Color::new(1.0, 0.5, 0.25));
    assert!(Film::from_raw(2, 2, vec![Sum::ZERO; 3], vec![0; 4]).is_none());
}

#[test]
fn ppm_is_plain_p3_with_one_triple_per_pixel_top_row_first() {
    let film = film_of(
        2,
        2,
        &[
            Some([1.0, 0.0, 0.0]),
            Some([0.0, 1.0, 0.0]),
            Some([0.0, 0.0, 1.0]),
            Some([0.25, 0.25, 0.25]),
        ],
    );
    let text = String::from_utf8(encode_ppm(&film, 2.0)).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines,
        [
            "P3",
            "2 2",
            "255",
            "255 0 0",
            "0 255 0",
            "0 0 255",
            "128 128 128"
        ]
    );
}

#[test]
fn pfm_is_linear_little_endian_bottom_row_first() {
    let film = film_of(
        2,
        2,
        &[
            Some([0.1, 0.2, 0.3]),
            None,
            Some([7.5, 0.0, 2.0]),
            Some([0.25; 3]),
        ],
    );
    let bytes = encode_pfm(&film);
    let header = b"PF\n2 2\n-1.0\n";
    assert_eq!(&bytes[..header.len()], header);
    let floats: Vec<f32> = bytes[header.len()..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    // Bottom row (y = 1) first; no gamma, no clamping.
    let expected = [
        7.5, 0.0, 2.0, 0.25, 0.25, 0.25, 0.1, 0.2, 0.3, 0.0, 0.0, 0.0,
    ];
    let expected: Vec<f32> = expected.iter().map(|&v: &f64| v as f32).collect();
    assert_eq!(floats, expected);
}

#[test]
fn every_format_round_trips_through_its_file() {
    let dir = scratch_dir("round-trip");
    let (w, h) = (5u32, 3u32);
    let pixels: Vec<Option<[f64; 3]>> = (0..w * h)
        .map(|i| Some([f64::from(i) / 8.0, 0.5, 1.5]))
        .collect();
    let film = film_of(w, h, &pixels);

    let png = dir.join("a.png");
    write_image(&png, &film, 2.0, &[]).unwrap();
    let decoded = image::open(&png).unwrap().into_rgb8();
    assert_eq!(decoded.dimensions(), (w, h));
    assert_eq!(decoded.into_raw(), film.to_rgb8(2.0));

    let exr_path = dir.join("a.exr");
    write_image(&exr_path, &film, 2.0, &[]).unwrap();
    let (size, exr_pixels) = common::read_exr_rgb(&exr_path);
    assert_eq!(size, (w as usize, h as usize));
    let linear: Vec<[f32; 3]> = film.linear().iter().map(|c| [c.x, c.y, c.z]).collect();
    assert_eq!(exr_pixels, linear, "EXR is linear, unclamped");

    for (ext, bytes) in [("ppm", encode_ppm(&film, 2.0)), ("pfm", encode_pfm(&film))] {
        let path = dir.join(format!("a.{ext}"));
        write_image(&path, &film, 2.0, &[]).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), bytes, "{ext}");
    }
    // Only the four images are left: no temporary files.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 4);
}

#[test]
fn unknown_extensions_and_bad_destinations_are_refused_without_a_file() {
    let dir = scratch_dir("refused");
    let film = film_of(1, 1, &[Some([0.5; 3])]);
    for name in ["a.jpg", "noextension", "a.PNG.txt"] {
        assert!(ImageFormat::from_path(Path::new(name)).is_err(), "{name}");
        let err = write_image(&dir.join(name), &film, 2.0, &[]).unwrap_err();
        assert!(err.to_string().contains(name), "{err}");
    }
    assert_eq!(
        ImageFormat::from_path(Path::new("A.PNG")).unwrap(),
        ImageFormat::Png
    );
    let missing = dir.join("no-such-dir").join("a.png");
    assert!(write_image(&missing, &film, 2.0, &[]).is_err());
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "a file was left behind"
    );
}

#[test]
fn colours_too_large_for_f32_are_refused_rather_than_rendered_as_infinity() {
    // 1e39 is a finite f64 but overflows f32: rendering it would turn every
    // sample into infinity and drop it.
    let mut desc = common::builtin_desc("albedo-grey", 8, 1, 0);
    desc.background = BackgroundDesc::Solid {
        color: [1e39, 1.0, 1.0],
    };
    let err = Scene::from_desc(&desc).unwrap_err().to_string();
    assert!(err.contains("background.color"), "{err}");
    desc.background = BackgroundDesc::Solid {
        color: [3e38, 1.0, 1.0],
    };
    assert!(Scene::from_desc(&desc).is_ok());
}

#[test]
fn the_same_film_gives_the_same_exr_file_every_time() {
    // Many blocks, compressed in parallel: they must still be written in
    // one order. Noise, so that blocks take different times to compress.
    let dir = scratch_dir("exr-order");
    let (w, h) = (1920u32, 1080u32);
    let mut x = 0x9e37_79b9u32;
    let pixels: Vec<Option<[f64; 3]>> = (0..w * h)
        .map(|i| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let v = if (i / 97) % 3 == 0 {
                0.25
            } else {
                f64::from(x) / 4e9
            };
            Some([v, 0.5, v * 2.0])
        })
        .collect();
    let film = film_of(w, h, &pixels);
    let first = dir.join("first.exr");
    write_image(&first, &film, 2.0, &[]).unwrap();
    let bytes = std::fs::read(&first).unwrap();
    for i in 0..6 {
        let again = dir.join(format!("again-{i}.exr"));
        write_image(&again, &film, 2.0, &[]).unwrap();
        assert!(std::fs::read(&again).unwrap() == bytes, "write {i} differs");
    }
}
