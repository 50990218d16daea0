//! A stop is honoured within moments even in the middle of a pass of very
//! long paths: SIGTERM, Ctrl-C and the time limit are looked at before every
//! pixel and every few hundred bounces, not only between rows, and the pass
//! cut short is abandoned whole (the film is as before it).

mod lumen_process;

use lumen::progressive::Session;
use lumen::scene::file::SceneFile;
use lumen::scene::Overrides;
use lumen_process::*;
use std::time::{Duration, Instant};

/// A camera inside a white fog (albedo 1) that fills a ball of radius 1e6:
/// its paths scatter millions of times before they get out.
const FOG: &str = "[render]\nwidth = 4\nheight = 2\nsamples_per_pixel = 4\nmax_depth = 1000000000\n\n\
[background]\ntype = \"solid\"\ncolor = [1, 1, 1]\n\n\
[[objects]]\ntype = \"medium\"\nboundary = { type = \"sphere\", center = [0, 0, 0], radius = 1e6 }\n\
density = 1\nalbedo = [1, 1, 1]\n";

#[test]
fn sigterm_during_a_pass_of_endless_paths_ends_the_render_in_moments() {
    let dir = temp_dir("stop-fog");
    let scene = dir.join("fog.toml");
    std::fs::write(&scene, FOG).unwrap();
    let out = dir.join("fog.png");
    let r = spawn(&["render", scene.to_str().unwrap()], &out, &[]);
    r.wait_line(&format!("{}:", scene.display()));
    std::thread::sleep(Duration::from_millis(300));
    let asked = Instant::now();
    r.signal(libc::SIGTERM);
    let (status, err) = r.finish();
    let took = asked.elapsed();
    assert!(
        took < Duration::from_secs(5),
        "took {took:?} to stop: {err}"
    );
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(err.contains("before the first pass finished"), "{err}");
    assert!(!out.exists());
}

#[test]
fn a_pass_asked_to_stop_mid_row_is_abandoned_whole() {
    let dir = temp_dir("stop-pass");
    let path = dir.join("fog.toml");
    std::fs::write(&path, FOG).unwrap();
    let (desc, _) = SceneFile::read(&path)
        .unwrap()
        .resolve(&Overrides::default())
        .unwrap();
    let mut session = Session::new(&desc).unwrap();
    let before = session.film().clone();
    let start = Instant::now();
    let stop_after = Duration::from_millis(200);
    let result = session.render_pass(&|_| {}, &|| start.elapsed() > stop_after);
    let took = start.elapsed();
    assert!(result.is_none(), "the pass was not abandoned");
    assert!(took < Duration::from_secs(5), "took {took:?}");
    assert!(*session.film() == before, "the film is as before the pass");
    assert_eq!(session.spp_done(), 0);
}
