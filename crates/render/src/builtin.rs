//! Built-in scenes, usable by name: their descriptions are the scene files in
//! the repository's `scenes/` directory, embedded in the binary together with
//! the images they use, so they render from anywhere.
//!
//! - `scene_ref`: the scene Mitsuba 3 rendered for `reference/scene_ref.exr`.
//! - `checkerboard`: matte, glossy and luster paper sheets in front of a
//!   checkerboard lit from behind (the supplement's Figure 1).
//! - `backlit`: folded sheets of three thicknesses, each lit from behind.
//! - `lightbox`: four layers of cut paper (masks from PNG files) in front of a
//!   light panel, like a paper-cut light box.

use crate::error::SceneError;
use crate::scene::Scene;
use crate::spec::{load_scene_str, Resources};
use std::collections::HashMap;

/// `(name, scene file text, embedded files)`.
type Builtin = (&'static str, &'static str, &'static [(&'static str, &'static [u8])]);

const BUILTINS: &[Builtin] = &[
    ("scene_ref", include_str!("../../../scenes/scene_ref.toml"), &[]),
    (
        "checkerboard",
        include_str!("../../../scenes/checkerboard.toml"),
        &[("checker_mask.png", include_bytes!("../../../scenes/checker_mask.png"))],
    ),
    ("backlit", include_str!("../../../scenes/backlit.toml"), &[]),
    (
        "lightbox",
        include_str!("../../../scenes/lightbox.toml"),
        &[
            (
                "lightbox_layer1.png",
                include_bytes!("../../../scenes/lightbox_layer1.png"),
            ),
            (
                "lightbox_layer2.png",
                include_bytes!("../../../scenes/lightbox_layer2.png"),
            ),
            (
                "lightbox_layer3.png",
                include_bytes!("../../../scenes/lightbox_layer3.png"),
            ),
            (
                "lightbox_layer4.png",
                include_bytes!("../../../scenes/lightbox_layer4.png"),
            ),
        ],
    ),
];

/// Names of the built-in scenes.
pub fn names() -> Vec<&'static str> {
    BUILTINS.iter().map(|b| b.0).collect()
}

/// The TOML text of a built-in scene.
pub fn source(name: &str) -> Option<&'static str> {
    BUILTINS.iter().find(|b| b.0 == name).map(|b| b.1)
}

/// Builds the built-in scene `name`; `None` if there is no such scene.
pub fn load(name: &str) -> Option<Result<Scene, SceneError>> {
    let b = BUILTINS.iter().find(|b| b.0 == name)?;
    let embedded: HashMap<String, &'static [u8]> = b.2.iter().map(|(k, v)| (k.to_string(), *v)).collect();
    let res = Resources {
        base_dir: std::path::PathBuf::from("."),
        embedded,
    };
    Some(load_scene_str(b.1, &format!("builtin:{name}"), &res))
}
