//! The TOML scene format (documented in `docs/scenes.md`) and its translation
//! into a [`Scene`].
//!
//! Every table rejects unknown keys; every error names the scene file and the
//! entry (`materials.NAME`, `shapes[i]`, `camera`, ...) and, for TOML syntax,
//! unknown keys and values of the wrong type, the line. The schema is in
//! `schema` (materials in `material`), the checks and translation in
//! `validate`, the error locator in `locate`; meshes are in [`crate::mesh`].

mod locate;
mod material;
mod schema;
mod validate;

pub use material::{DielectricSpec, DiffuseSpec, MaterialSpec, MaterialType, MeasuredSpec, PaperSpec};
pub use schema::{
    CameraSpec, ColourSpec, EnvironmentSpec, InkMapSpec, RenderSpec, SceneSpec, ShapeSpec, TextureSpec,
    ThicknessMapSpec, TransformSpec,
};
pub use validate::build;

use crate::error::{ImageError, SceneError};
use crate::scene::Scene;
use crate::texture::Image;
use paperbsdf_io::{DataError, MeasuredBsdf};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where files named in a scene come from: a directory, and files embedded in the binary (built-in scenes).
pub struct Resources {
    /// Directory relative paths are resolved against.
    pub base_dir: PathBuf,
    /// Embedded files by relative path.
    pub embedded: HashMap<String, &'static [u8]>,
}

impl Resources {
    /// Decodes an image (embedded, else relative to the base directory); the
    /// error names the file.
    fn image(&self, rel: &str, grey: bool) -> Result<Arc<Image>, ImageError> {
        if let Some(b) = self.embedded.get(rel) {
            return Image::from_bytes(b, grey).map(Arc::new);
        }
        let p = self.base_dir.join(rel);
        Image::load(&p, grey).map(Arc::new)
    }

    /// Reads a measured RGL `.bsdf` file (embedded, else relative to the base directory);
    /// the error names the file's path and what is wrong with it.
    fn measured(&self, rel: &str) -> Result<MeasuredBsdf, DataError> {
        if let Some(b) = self.embedded.get(rel) {
            return MeasuredBsdf::from_bytes(b.to_vec(), rel);
        }
        MeasuredBsdf::load(self.base_dir.join(rel))
    }
}

/// Reads and builds a scene file.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| SceneError {
        file: file.clone(),
        entry: "file".into(),
        message: format!("cannot read: {e}"),
    })?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    load_scene_str(
        &text,
        &file,
        &Resources {
            base_dir: base,
            embedded: HashMap::new(),
        },
    )
}

/// Parses and builds a scene from TOML text; `file` names it in errors.
pub fn load_scene_str(text: &str, file: &str, res: &Resources) -> Result<Scene, SceneError> {
    let spec: SceneSpec = toml::from_str(text).map_err(|e| {
        let entry = match e.span() {
            Some(s) => locate::entry_at(text, s.start.min(text.len())),
            None => "toml".to_string(),
        };
        SceneError {
            file: file.to_string(),
            entry,
            message: e.message().to_string(),
        }
    })?;
    build(&spec, file, res)
}
