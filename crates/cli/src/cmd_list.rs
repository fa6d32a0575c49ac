//! `paperbsdf list`: the models with their parameters (names, units and ranges
//! of docs/design.md section 3) and the paper presets of `paperbsdf_core::presets`
//! with their values, so that a newcomer can pick one by name
//! (`--params matte`) without reading the source.

use anyhow::Result;
use paperbsdf_core::presets::{preset, PRESET_NAMES};

/// Arguments of `paperbsdf list`.
#[derive(clap::Args, Debug)]
pub struct ListArgs {
    /// What to list.
    #[arg(value_enum, default_value_t = What::All, ignore_case = true)]
    pub what: What,
}

/// What `paperbsdf list` prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum What {
    /// The models with their parameters.
    Models,
    /// The paper presets with their values.
    Presets,
    /// Both.
    All,
}

/// The parameters of the Paper BSDF: name, range, meaning (docs/design.md section 3).
pub const PAPER_PARAMS: [(&str, &str, &str); 13] = [
    ("d", "(0, inf) mm", "thickness"),
    ("sigma_a", "[0, inf) 1/mm, number or [r,g,b]", "absorption coefficient"),
    ("sigma_s", "[0, inf) 1/mm, number or [r,g,b]", "scattering coefficient"),
    ("g_f", "[-1, 1]", "mean cosine of the forward Henyey-Greenstein lobe"),
    ("g_b", "[-1, 1]", "mean cosine of the backward lobe"),
    ("w_b", "[0, 1]", "weight of the backward lobe (forward: 1 - w_b)"),
    ("eta_f", "[1, 5]", "relative index of the front face (z = 0)"),
    ("eta_b", "[1, 5]", "relative index of the back face (z = -d)"),
    ("m_f", "[0, pi/2]", "microfacet roughness (alpha) of the front face"),
    ("m_b", "[0, pi/2]", "microfacet roughness of the back face"),
    ("dist_f", "ggx or beckmann", "microfacet distribution of the front face"),
    ("dist_b", "ggx or beckmann", "microfacet distribution of the back face"),
    (
        "face_scattering",
        "multiple (default) or single",
        "optional: energy-conserving faces, or Walter's single-scattering faces",
    ),
];

/// The text `paperbsdf list WHAT` prints.
pub fn listing(what: What) -> Result<String> {
    let models = what != What::Presets;
    let presets = what != What::Models;
    let mut s = String::new();
    if models {
        s.push_str(
            "models (--model NAME; parameters by name in a JSON/TOML file, inline JSON, a preset or a FIT.json):\n",
        );
        s.push_str("  paper               the Paper BSDF (Papas, de Mesa, Jensen 2014):\n");
        for (n, r, m) in PAPER_PARAMS {
            s.push_str(&format!("                        {n:<16} {r:<34} {m}\n"));
        }
        s.push_str("                        name             optional label\n");
        s.push_str("  reduced-multilayer  the same parameters; every rough-face attenuation Att set to 1\n");
        s.push_str("  lambert-glass       Lambert layer under rough glass (the paper's Figure 4 baseline):\n");
        for (n, r, m) in [
            ("k_d", "[0, 1], number or [r,g,b]", "Lambertian reflectance"),
            (
                "k_t",
                "[0, 1], number or [r,g,b]",
                "Lambertian transmittance (k_d + k_t <= 1)",
            ),
            ("eta", "[1, 5]", "relative index of the glass faces"),
            ("m", "[0, pi/2]", "roughness of both faces"),
            ("dist", "ggx or beckmann", "microfacet distribution"),
        ] {
            s.push_str(&format!("                        {n:<16} {r:<34} {m}\n"));
        }
        s.push_str("  rough-dielectric    one rough dielectric interface (Walter et al. 2007):\n");
        for (n, r, m) in [
            ("eta", "[1, 5]", "relative index, interior (z < 0) over exterior"),
            ("m", "[0, pi/2]", "roughness (alpha)"),
            ("dist", "ggx or beckmann", "microfacet distribution"),
        ] {
            s.push_str(&format!("                        {n:<16} {r:<34} {m}\n"));
        }
    }
    if presets {
        if models {
            s.push('\n');
        }
        s.push_str(
            "paper presets (--params NAME, or `preset = \"NAME\"` in a scene; models paper and reduced-multilayer):\n",
        );
        for name in PRESET_NAMES {
            let p = preset(name).expect("listed presets exist");
            let json = serde_json::to_string(&p)?;
            s.push_str(&format!("  {name:<8} {json}\n"));
        }
    }
    Ok(s)
}

/// Runs `paperbsdf list`.
pub fn run(a: ListArgs) -> Result<()> {
    print!("{}", listing(a.what)?);
    Ok(())
}
