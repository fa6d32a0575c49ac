//! Property-based fuzzing (proptest) of the renderer's readers: scene files
//! (TOML), OBJ meshes and texture images. Arbitrary bytes and structured
//! near-valid inputs load or give an error naming the file, never a panic, and
//! never a large allocation (a counting allocator records the largest single
//! request; every input here is a few kB or a header claiming a huge image, so
//! a request above 64 MiB is unbounded growth). About ten seconds on 2 cores.

use paperbsdf_render::spec::Resources;
use paperbsdf_render::texture::Image;
use paperbsdf_render::{load_scene, load_scene_str};
use proptest::prelude::*;
use std::collections::HashMap;

#[path = "../../io/tests/common/largest_alloc.rs"]
mod largest_alloc;

fn bounded() {
    largest_alloc::assert_bounded(64 << 20);
}

const GOOD: &str = r#"
[render]
width = 8
height = 6

[camera]
origin = [0, -3, 1]
target = [0, 0, 0]
fov = 40

[materials.board]
type = "diffuse"
reflectance = { type = "checker", even = 0.8, odd = 0.1 }

[materials.sheet]
type = "paper"
preset = "matte"

[[shapes]]
name = "floor"
type = "rectangle"
material = "board"

[[shapes]]
name = "lamp"
type = "sphere"
center = [0, 0, 3]
radius = 0.5
emission = [4, 4, 4]

[[shapes]]
name = "fold"
type = "folded"
material = "sheet"
panels = 4

[[shapes]]
name = "statue"
type = "obj"
file = "statue.obj"
material = "board"
"#;

fn res(dir: &std::path::Path) -> Resources {
    Resources {
        base_dir: dir.to_path_buf(),
        embedded: HashMap::new(),
    }
}

fn check_scene(text: &str, dir: &std::path::Path) {
    if let Err(e) = load_scene_str(text, "fuzz.toml", &res(dir)) {
        assert!(e.to_string().contains("fuzz.toml"), "{e}");
    }
    bounded();
}

/// The smallest valid PNG header (signature and IHDR) for a `w x h` RGB image, with no data.
fn png_header(w: u32, h: u32) -> Vec<u8> {
    let mut v = vec![0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0, 13];
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend_from_slice(&w.to_be_bytes());
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    let crc = crc32(&ihdr);
    v.extend_from_slice(&ihdr);
    v.extend_from_slice(&crc.to_be_bytes());
    v
}

fn crc32(b: &[u8]) -> u32 {
    let mut c = 0xffff_ffffu32;
    for &x in b {
        c ^= x as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xedb8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

/// The structured cases start from a scene that loads.
#[test]
fn the_base_scene_loads() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("statue.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let s = load_scene_str(GOOD, "fuzz.toml", &res(dir.path())).unwrap();
    assert_eq!(s.settings.width, 8);
}

/// A header claiming a 100000 x 100000 image (30 GB) is refused before decoding.
#[test]
fn huge_image_header_is_refused_without_allocating() {
    let e = Image::from_bytes(&png_header(100_000, 100_000), false).unwrap_err();
    assert!(e.contains("limit") || e.contains("Limit"), "{e}");
    let e = Image::from_bytes(&png_header(16_000, 16_000), true).unwrap_err();
    assert!(!e.is_empty());
    bounded();
}

const TOML_BITS: &[&str] = &[
    "[render]",
    "[camera]",
    "[materials.a]",
    "[[shapes]]",
    "\n",
    " = ",
    "width",
    "height",
    "spp",
    "origin",
    "target",
    "fov",
    "up",
    "type",
    "\"paper\"",
    "\"diffuse\"",
    "\"sphere\"",
    "\"rectangle\"",
    "\"obj\"",
    "\"folded\"",
    "material",
    "\"a\"",
    "preset",
    "\"matte\"",
    "radius",
    "emission",
    "panels",
    "file",
    "\"statue.obj\"",
    "[0, 0, 1]",
    "[1, 2]",
    "0",
    "1e9",
    "-1",
    "nan",
    "inf",
    "{ type = \"checker\" }",
    "reflectance",
    "transform",
    "[{ scale = 0 }]",
    "\"",
    "\u{feff}",
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn scene_from_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let dir = tempfile::tempdir().unwrap();
        check_scene(&String::from_utf8_lossy(&bytes), dir.path());
    }

    #[test]
    fn scene_from_near_valid_toml(parts in prop::collection::vec(prop_oneof![
        4 => prop::sample::select(TOML_BITS).prop_map(str::to_string),
        1 => "[ -~\\n]{0,6}",
    ], 0..60)) {
        let dir = tempfile::tempdir().unwrap();
        check_scene(&parts.concat(), dir.path());
    }

    /// Structured values: one number of a valid scene replaced by an
    /// arbitrary one (huge, negative, non-finite), or one line dropped.
    #[test]
    fn scene_with_one_value_changed(line in 0usize..60, value in prop_oneof![
        prop::num::f64::ANY.prop_map(|x| format!("{x:e}")),
        any::<i64>().prop_map(|x| x.to_string()),
        Just("[]".to_string()), Just("\"x\"".to_string()), Just("[1, 2]".to_string()),
    ], drop in any::<bool>()) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("statue.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let lines: Vec<String> = GOOD.lines().enumerate().filter_map(|(i, l)| {
            if i != line % 60 { return Some(l.to_string()); }
            if drop { return None; }
            Some(match l.split_once(" = ") { Some((k, _)) => format!("{k} = {value}"), None => l.to_string() })
        }).collect();
        check_scene(&lines.join("\n"), dir.path());
    }

    #[test]
    fn obj_from_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("statue.obj"), &bytes).unwrap();
        check_scene(GOOD, dir.path());
    }

    /// Structured meshes: vertices with arbitrary numbers and faces with arbitrary indices.
    #[test]
    fn obj_with_arbitrary_numbers(vs in prop::collection::vec(prop::array::uniform3(prop::num::f32::ANY), 0..8),
                                  fs in prop::collection::vec(prop::array::uniform3(-10i64..10), 0..8)) {
        let dir = tempfile::tempdir().unwrap();
        let mut t = String::new();
        for v in &vs { t.push_str(&format!("v {} {} {}\n", v[0], v[1], v[2])); }
        for f in &fs { t.push_str(&format!("f {} {} {}\n", f[0], f[1], f[2])); }
        std::fs::write(dir.path().join("statue.obj"), &t).unwrap();
        let p = dir.path().join("scene.toml");
        std::fs::write(&p, GOOD).unwrap();
        match load_scene(&p) {
            Ok(_) => assert!(vs.iter().flatten().all(|x| x.is_finite()), "a non-finite vertex was accepted:\n{t}"),
            Err(e) => assert!(e.to_string().contains("scene.toml"), "{e}"),
        }
        bounded();
    }

    #[test]
    fn image_from_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..400), grey in any::<bool>(),
                                  w in 0u32..200_000, h in 0u32..200_000) {
        let _ = Image::from_bytes(&bytes, grey);
        // A valid signature and header with arbitrary size and truncated or noisy data.
        let mut png = png_header(w, h);
        png.extend_from_slice(&bytes);
        let _ = Image::from_bytes(&png, grey);
        bounded();
    }
}
