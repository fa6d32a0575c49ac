//! `paperbsdf render`: renders a TOML scene file or a built-in scene with the
//! path tracer of `paperbsdf-render`, writing `FILE.exr` (linear radiance) and
//! `FILE.png` (tone-mapped sRGB), each atomically. Ctrl-C stops the render
//! and still writes the image accumulated so far, then exits with code 130.
//! The output stem is kept as given (`--out run.v2` writes `run.v2.exr` and
//! `run.v2.png`; a final `.exr` or `.png` is dropped); both paths are checked
//! before the render starts, as is the memory the image needs.

use paperbsdf_render::{builtin, film, RenderOptions};
use std::path::{Path, PathBuf};

/// Arguments of `paperbsdf render`.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// A scene file (`.toml`) or a built-in scene: scene_ref, checkerboard, backlit, lightbox.
    pub scene: String,
    /// Samples per pixel (default: the scene's `render.spp`).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Output file stem: writes STEM.exr and STEM.png, the stem kept as given (a final .exr or .png is dropped; default: the scene's name in the current directory).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Random seed (default: the scene's `render.seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Number of worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Image width, pixels (default: the scene's).
    #[arg(long)]
    pub width: Option<usize>,
    /// Image height, pixels (default: the scene's).
    #[arg(long)]
    pub height: Option<usize>,
}

/// Runs `paperbsdf render`.
pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    let path = Path::new(&args.scene);
    let mut scene = if path.exists() || args.scene.ends_with(".toml") {
        paperbsdf_render::load_scene(path)?
    } else {
        match builtin::load(&args.scene) {
            Some(s) => s?,
            None => anyhow::bail!(
                "`{}` is neither a scene file nor a built-in scene (built-in: {})",
                args.scene,
                builtin::names().join(", ")
            ),
        }
    };
    if let Some(s) = args.spp {
        anyhow::ensure!(s >= 1, "--spp must be at least 1");
        scene.settings.spp = s;
    }
    if let Some(s) = args.seed {
        scene.settings.seed = s;
    }
    if args.width.is_some() || args.height.is_some() {
        let (w0, h0) = (scene.settings.width, scene.settings.height);
        let w = args
            .width
            .unwrap_or_else(|| (args.height.unwrap_or(h0) * w0).div_ceil(h0));
        let h = args.height.unwrap_or_else(|| (w * h0).div_ceil(w0));
        anyhow::ensure!(
            (1..=16384).contains(&w) && (1..=16384).contains(&h),
            "image size {w}x{h} is outside 1..16384"
        );
        scene.settings.width = w;
        scene.settings.height = h;
    }
    let stem = match args.out {
        Some(o) => {
            let ext = o.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
            if matches!(ext.as_deref(), Some("exr") | Some("png")) {
                o.with_extension("")
            } else {
                o
            }
        }
        None => PathBuf::from(
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "render".into()),
        ),
    };
    let exr = with_suffix(&stem, "exr");
    let png = with_suffix(&stem, "png");
    paperbsdf_io::check_output_path(&exr, "--out")?;
    paperbsdf_io::check_output_path(&png, "--out")?;
    let (w, h) = (scene.settings.width, scene.settings.height);
    paperbsdf_render::check_memory(w, h, paperbsdf_render::available_memory_bytes()).map_err(anyhow::Error::msg)?;
    let cancel = paperbsdf_render::install_ctrlc_flag().map_err(anyhow::Error::msg)?;
    let spp = scene.settings.spp;
    let opts = RenderOptions {
        spp,
        pass_spp: spp.clamp(1, 4),
        progress: true,
    };
    let (out, nthreads) =
        paperbsdf_render::render_with_threads(&scene, &opts, cancel, args.threads).map_err(anyhow::Error::msg)?;
    let img = out.film.image();
    film::write_exr(&exr, w, h, &img).map_err(anyhow::Error::msg)?;
    film::write_png(&png, w, h, &img, scene.settings.exposure).map_err(anyhow::Error::msg)?;
    let mean = img.iter().fold(paperbsdf_core::Rgb::ZERO, |a, &b| a + b) / img.len() as f64;
    let summary = format!(
        "{}{}x{} at {} spp in {:.2} s ({:.3} M samples/s, {} threads); mean radiance ({:.4}, {:.4}, {:.4}); wrote {} and {}",
        if out.cancelled { "INTERRUPTED: " } else { "" },
        w,
        h,
        if out.cancelled { format!("{}..{}", out.film.min_count(), spp) } else { spp.to_string() },
        out.elapsed.as_secs_f64(),
        out.samples_per_second() / 1e6,
        nthreads,
        mean.0[0],
        mean.0[1],
        mean.0[2],
        exr.display(),
        png.display()
    );
    if out.cancelled {
        return Err(crate::Interrupted(summary).into());
    }
    eprintln!("{summary}");
    Ok(())
}

/// `stem` with `.ext` appended to its file name (not replacing an extension:
/// `run.v2` gives `run.v2.exr`).
fn with_suffix(stem: &Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_os_string();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn stem_is_kept_as_given() {
        // Issue 16: `--out run.v2` wrote run.exr, replacing what `--out run.v3` wrote.
        assert_eq!(
            with_suffix(Path::new("out/run.v2"), "exr"),
            PathBuf::from("out/run.v2.exr")
        );
        assert_eq!(with_suffix(Path::new("run"), "png"), PathBuf::from("run.png"));
    }
}
