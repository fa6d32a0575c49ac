//! The renderer's errors: [`SceneError`] for a scene description that cannot be
//! built (it names the file and the entry), [`ImageError`] for an image that
//! cannot be decoded, and [`RenderError`] for everything else (cameras, meshes,
//! output files, threads, memory).
//!
//! Each message says what is wrong with the values involved; none of them
//! repeats a cause as a separate [`std::error::Error::source`], so a caller
//! printing the chain of causes prints each message once.

use glam::DVec3;
use std::path::PathBuf;

/// An error in a scene description: the file, the entry and what is wrong.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{file}: {entry}: {message}")]
pub struct SceneError {
    /// The scene file (or `builtin:NAME`).
    pub file: String,
    /// The entry, e.g. `materials.glass` or `shapes[2]`.
    pub entry: String,
    /// What is wrong.
    pub message: String,
}

/// An image (a texture, mask or map) that cannot be read or decoded, or is
/// larger than the limits of [`crate::texture::Image::load`]. The message names
/// the file (or says the image was embedded) and gives the decoder's reason; the
/// error dereferences to it, so it can be searched like a string.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{0}")]
pub struct ImageError(pub(crate) String);

impl std::ops::Deref for ImageError {
    type Target = str;
    fn deref(&self) -> &str {
        &self.0
    }
}

/// An error of the renderer outside the scene description itself.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The camera's origin and target are the same point.
    #[error("camera origin and target coincide")]
    CameraTarget,
    /// The camera's `up` is (nearly) parallel to its viewing direction.
    #[error(
        "camera `up` = ({}, {}, {}) is parallel to the viewing direction (the angle between them must be at least {:.4} degrees)",
        .up.x, .up.y, .up.z, crate::scene::UP_MIN_SIN.asin().to_degrees()
    )]
    CameraUp {
        /// The `up` given.
        up: DVec3,
    },
    /// The camera's field of view is outside (0, 180) degrees.
    #[error("camera fov = {fov} is outside (0, 180) degrees")]
    CameraFov {
        /// The horizontal field of view given, degrees.
        fov: f64,
    },
    /// An OBJ file that cannot be read or parsed.
    #[error("cannot load OBJ '{}': {reason}", .path.display())]
    ObjLoad {
        /// The file.
        path: PathBuf,
        /// The reader's or parser's message.
        reason: String,
    },
    /// A vertex, normal or texture coordinate of an OBJ file that is not finite.
    #[error("OBJ '{}' line {line}: `{keyword}` has the non-finite number `{number}`", .path.display())]
    ObjNumber {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// `v`, `vn` or `vt`.
        keyword: String,
        /// The number as written.
        number: String,
    },
    /// A face of an OBJ file that refers to a vertex that does not exist.
    #[error("OBJ '{}': face index out of range in object `{object}`", .path.display())]
    ObjFaceIndex {
        /// The file.
        path: PathBuf,
        /// The object (`o`) holding the face.
        object: String,
    },
    /// An OBJ file without a single triangle of non-zero area.
    #[error("OBJ '{}' has no triangles", .path.display())]
    ObjEmpty {
        /// The file.
        path: PathBuf,
    },
    /// An output image that cannot be written (or an input one that cannot be
    /// read back): `format` is `EXR` or `PNG`.
    #[error("cannot {verb} {format} '{}': {reason}", .path.display())]
    ImageFile {
        /// `read` or `write`.
        verb: &'static str,
        /// `EXR` or `PNG`.
        format: &'static str,
        /// The file.
        path: PathBuf,
        /// The encoder's or decoder's message.
        reason: String,
    },
    /// A pixel buffer whose length does not match the image size.
    #[error("image buffer size mismatch")]
    BufferSize,
    /// The atomic write of an output file failed (its path is refused, or the
    /// temporary file cannot be created or renamed).
    #[error("{0}")]
    Output(paperbsdf_io::DataError),
    /// The image needs more memory than is available.
    #[error(
        "a {width}x{height} render needs about {:.1} GB of memory, more than the {:.1} GB available; use a smaller --width/--height",
        .need / 1e9, .available / 1e9
    )]
    Memory {
        /// Image width, pixels.
        width: usize,
        /// Image height, pixels.
        height: usize,
        /// Estimated need, bytes.
        need: f64,
        /// Available memory, bytes.
        available: f64,
    },
    /// A render asked for zero worker threads.
    #[error("--threads must be at least 1")]
    NoThreads,
    /// The worker threads cannot be started.
    #[error("cannot start the worker threads: {0}")]
    Threads(rayon::ThreadPoolBuildError),
    /// The Ctrl-C handler cannot be installed (one is installed already).
    #[error("cannot install the Ctrl-C handler: {0}")]
    CtrlC(ctrlc::Error),
}
