//! `paperbsdf simulate`: the ground truth. Monte Carlo simulation of the physical
//! paper slab (crate `paperbsdf-sim`): in-plane BSDF values with standard errors,
//! or total reflectance and transmittance, in the conventions of docs/design.md
//! section 2 (`f` without cosine; `theta_o` signed, negative on the side
//! opposite the light; `R` rows seen from `z > 0`, `T` rows from `z < 0`).

use anyhow::{bail, Context, Result};
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::{DVec3, PaperParams, Rgb};
use paperbsdf_io::angles::check_angles;
use paperbsdf_sim::{simulate_bsdf, simulate_totals, Estimate, Incidence, SimConfig, Slab, Totals};
use std::ops::Bound::Excluded;

/// Arguments of `paperbsdf simulate`.
#[derive(clap::Args, Debug)]
pub struct SimulateArgs {
    /// Paper parameters: a JSON or TOML file, inline JSON, a FIT.json, or a preset (matte, luster, glossy).
    #[arg(long)]
    pub params: String,
    /// In-plane incident angles in degrees, comma-separated, in [0, 90).
    #[arg(long = "theta-i", value_delimiter = ',')]
    pub theta_i: Vec<f64>,
    /// In-plane viewing angles FROM:TO:STEP in degrees, in (-90, 90); both R and T rows are printed.
    #[arg(long = "theta-o", allow_hyphen_values = true)]
    pub theta_o: Option<String>,
    /// Print total reflectance and transmittance per incident angle instead of BSDF values.
    #[arg(long, conflicts_with = "theta_o")]
    pub totals: bool,
    /// With --totals: diffuse (cosine-weighted) incident light on the front face instead of --theta-i.
    #[arg(long, requires = "totals", conflicts_with = "theta_i")]
    pub diffuse: bool,
    /// Random walks per incident angle (and colour channel).
    #[arg(long, conflicts_with = "rel_stderr")]
    pub samples: Option<u64>,
    /// Keep simulating until every positive estimate has a standard error below this fraction of its value.
    #[arg(long = "rel-stderr")]
    pub rel_stderr: Option<f64>,
    /// Upper limit of walks per incident angle with --rel-stderr (at least 1).
    #[arg(long = "max-samples", default_value_t = 1 << 26)]
    pub max_samples: u64,
    /// Independent batches the walks are split into (standard errors come from their spread), 2 to 100000.
    #[arg(long, default_value_t = 32)]
    pub batches: u32,
    /// Refuse runs predicted to take more collisions than this (the prediction
    /// and the time it means are printed); raise it to run anyway.
    #[arg(long = "max-collisions", default_value_t = DEFAULT_MAX_COLLISIONS)]
    pub max_collisions: f64,
    /// Cut each random walk after this many scattering events, 1 or more
    /// (the default cuts nothing in paper). Cut walks are counted, and a
    /// warning says how much of the incident flux they took with them.
    #[arg(long = "max-walk-collisions", default_value_t = paperbsdf_sim::walk::MAX_COLLISIONS_PER_WALK as u64)]
    pub max_walk_collisions: u64,
    /// Seed; the output is reproducible for a given seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write the table to this file (atomically) instead of standard output.
    #[arg(long)]
    pub out: Option<String>,
}

/// Default walks per incident angle when neither --samples nor --rel-stderr is given.
const DEFAULT_SAMPLES: u64 = 1 << 16;
/// First round of walks with --rel-stderr.
const ADAPTIVE_FIRST_ROUND: u64 = 1 << 13;
/// Default of `--max-collisions`: 2e10 collisions, about 10 to 30 minutes on
/// two cores (the collision rate with one viewing direction is 1e7 to 3e7 per
/// second there); paper at the default 65536 walks takes about 1e8.
pub const DEFAULT_MAX_COLLISIONS: f64 = 2e10;
/// Most viewing angles in one run: every angle adds two next-event
/// estimates (R and T) to every collision of every walk, so the run's time
/// grows with their number (eval, which costs nothing per angle, allows 100000).
pub const MAX_VIEW_ANGLES: usize = 1000;

/// Loads and validates the parameters; errors name the file, line and parameter.
fn load(source: &str) -> Result<PaperParams> {
    let l = paperbsdf_io::load_params::<PaperParams>(source)?;
    if let Err(e) = l.value.validate() {
        return Err(l.param_error(e).into());
    }
    Ok(l.value)
}

fn config(a: &SimulateArgs) -> Result<SimConfig> {
    if let Some(x) = a.rel_stderr {
        if !(x > 0.0 && x < 1.0) {
            bail!("--rel-stderr = {x} is outside the allowed range (0, 1)");
        }
    }
    if a.samples == Some(0) {
        bail!("--samples = 0: need at least one walk");
    }
    if a.max_samples == 0 {
        bail!("--max-samples = 0: need at least one walk");
    }
    if !(2..=paperbsdf_sim::estimate::MAX_BATCHES).contains(&a.batches) {
        bail!(
            "--batches = {} is outside the allowed range [2, {}] (at least 2 for a standard error)",
            a.batches,
            paperbsdf_sim::estimate::MAX_BATCHES
        );
    }
    if a.max_collisions.is_nan() || a.max_collisions <= 0.0 {
        bail!("--max-collisions = {} must be positive", a.max_collisions);
    }
    if a.max_walk_collisions == 0 {
        bail!(
            "--max-walk-collisions = 0 is outside the allowed range [1, {}] (scattering events per walk)",
            u64::MAX
        );
    }
    let samples = match (a.samples, a.rel_stderr) {
        (Some(n), _) => n,
        (None, Some(_)) => ADAPTIVE_FIRST_ROUND,
        (None, None) => DEFAULT_SAMPLES,
    };
    Ok(SimConfig {
        samples: samples.max(a.batches as u64),
        batches: a.batches,
        seed: a.seed,
        rel_stderr: a.rel_stderr,
        max_samples: a.max_samples,
        progress: true,
        by_order: false,
        max_collisions_per_walk: a.max_walk_collisions,
    })
}

/// Refuses a run predicted to take more than `max_collisions` collisions
/// (`--max-collisions`), with the reason and the estimated time (from a short
/// pilot of walks).
fn check_work(
    max_collisions: f64,
    slab: &Slab,
    cfg: &SimConfig,
    wi: DVec3,
    wos: &[DVec3],
    n_dirs: usize,
) -> Result<()> {
    let w = paperbsdf_sim::estimate::estimate_work(slab, cfg, n_dirs);
    if w.collisions <= max_collisions {
        return Ok(());
    }
    let rate = paperbsdf_sim::estimate::measure_collision_rate(slab, wi, wos, 0.3);
    let m = (0..3).map(|c| slab.medium(c)).fold(slab.medium(0), |x, y| {
        if y.sigma_t * slab.d > x.sigma_t * slab.d {
            y
        } else {
            x
        }
    });
    bail!(
        "this run would take about {:.1e} collisions ({:.0e} walks of about {:.0} collisions each), \
about {} at the measured {:.1e} collisions/s, more than --max-collisions = {:.1e}: the slab is \
{:.3e} mean free paths thick (sigma_t * d) with single-scattering albedo {:.6}; \
lower --samples or raise --max-collisions to run anyway",
        w.collisions,
        w.walks,
        w.collisions_per_walk,
        human_time(w.collisions / rate),
        rate,
        max_collisions,
        m.sigma_t * slab.d,
        m.albedo
    )
}

/// `3.2 s`, `4.5 min`, `2.1 h`, `3.0 days`.
fn human_time(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.1} s")
    } else if s < 7200.0 {
        format!("{:.1} min", s / 60.0)
    } else if s < 172_800.0 {
        format!("{:.1} h", s / 3600.0)
    } else {
        format!("{:.1e} days", s / 86400.0)
    }
}

/// Notes on a run for the end of the output: achieved precision, walks cut.
fn run_notes(
    what: &str,
    cfg: &SimConfig,
    samples: u64,
    truncated: u64,
    worst: f64,
    reached: bool,
    notes: &mut Vec<String>,
) {
    if let Some(x) = cfg.rel_stderr {
        let status = if reached {
            "reached".to_string()
        } else {
            format!("NOT reached: stopped by --max-samples {}", cfg.max_samples)
        };
        notes.push(format!(
            "{what}: {samples} walks, worst relative standard error {worst:.3e} (target {x:e} {status})"
        ));
        if !reached {
            eprintln!(
                "warning: {what}: --rel-stderr {x:e} not reached after {samples} walks (--max-samples); \
the worst relative standard error is {worst:.3e}"
            );
        }
    }
    if truncated > 0 {
        let m = format!(
            "WARNING {what}: {truncated} walks were cut at {} collisions (--max-walk-collisions); \
their remaining flux (at most {:.3e} of the incident flux) is missing from these estimates",
            cfg.max_collisions_per_walk,
            truncated as f64 / samples.max(1) as f64
        );
        eprintln!("warning: {}", m.trim_start_matches("WARNING "));
        notes.push(m);
    }
}

/// One row of the totals table, `label,` then reflectance and transmittance;
/// the notes on the run (`what`) go to `notes`.
fn totals_row(label: &str, what: &str, t: &Totals, cfg: &SimConfig, rgb: bool, notes: &mut Vec<String>) -> String {
    run_notes(
        what,
        cfg,
        t.samples,
        t.truncated,
        t.worst_rel_stderr,
        t.target_reached,
        notes,
    );
    format!(
        "{label},{},{}\n",
        fmt_estimate(&t.reflectance, rgb),
        fmt_estimate(&t.transmittance, rgb)
    )
}

/// The in-plane viewing directions at incidence `ti` and angles `to`: the
/// `R` rows, then the `T` rows (the order of the table and of [`simulate_bsdf`]'s values).
fn view_dirs(ti: f64, to: &[f64]) -> Vec<DVec3> {
    [false, true]
        .iter()
        .flat_map(|&t| to.iter().map(move |&o| in_plane_directions(ti, o, t).1))
        .collect()
}

fn fmt(v: f64) -> String {
    format!("{v:.6e}")
}

/// `f,stderr` for scalar parameters, `r,g,b,r_stderr,g_stderr,b_stderr` for RGB.
fn fmt_estimate(e: &Estimate, rgb: bool) -> String {
    if rgb {
        let c = |x: Rgb| x.0.iter().map(|&v| fmt(v)).collect::<Vec<_>>().join(",");
        format!("{},{}", c(e.mean), c(e.stderr))
    } else {
        format!("{},{}", fmt(e.mean.0[0]), fmt(e.stderr.0[0]))
    }
}

fn header_line(p: &PaperParams, cfg: &SimConfig) -> String {
    let json = serde_json::to_string(p).unwrap_or_default();
    let mode = match cfg.rel_stderr {
        Some(x) => format!(
            "until rel. stderr <= {x} (first round {} walks, max {})",
            cfg.samples, cfg.max_samples
        ),
        None => format!("{} walks per incident angle and channel", cfg.samples),
    };
    let cap = if cfg.max_collisions_per_walk == paperbsdf_sim::walk::MAX_COLLISIONS_PER_WALK as u64 {
        String::new()
    } else {
        format!(", walks cut at {} collisions", cfg.max_collisions_per_walk)
    };
    format!(
        "# paperbsdf simulate (Monte Carlo ground truth, paperbsdf-sim {}): f without cosine, theta_o < 0 opposite the light; {mode}{cap}, {} batches, seed {}; params: {json}\n",
        env!("CARGO_PKG_VERSION"),
        cfg.batches,
        cfg.seed
    )
}

/// Runs `paperbsdf simulate`.
pub fn run(a: SimulateArgs) -> Result<()> {
    if let Some(out) = &a.out {
        paperbsdf_io::check_output_path(out, "--out")?;
    }
    let p = load(&a.params)?;
    let slab = Slab::from_params(&p).with_context(|| format!("parameters `{}`", a.params))?;
    paperbsdf_sim::estimate::check_slab(&slab).with_context(|| format!("parameters `{}`", a.params))?;
    let cfg = config(&a)?;
    let rgb = slab.rgb;
    let mut text = header_line(&p, &cfg);
    let mut notes = Vec::new();
    if a.totals {
        let cols = if rgb {
            "R_r,R_g,R_b,R_r_stderr,R_g_stderr,R_b_stderr,T_r,T_g,T_b,T_r_stderr,T_g_stderr,T_b_stderr"
        } else {
            "R,R_stderr,T,T_stderr"
        };
        if a.diffuse {
            text.push_str(&format!("incidence,{cols}\n"));
            check_work(a.max_collisions, &slab, &cfg, DVec3::Z, &[], 1)?;
            let t = simulate_totals(&slab, Incidence::Diffuse { front: true }, &cfg)?;
            text.push_str(&totals_row("diffuse", "diffuse", &t, &cfg, rgb, &mut notes));
        } else {
            if a.theta_i.is_empty() {
                bail!("--totals needs --theta-i LIST (degrees) or --diffuse");
            }
            check_angles(&a.theta_i, "--theta-i", 0.0..90.0)?;
            text.push_str(&format!("theta_i_deg,{cols}\n"));
            let (wi0, _) = in_plane_directions(a.theta_i[0], 0.0, false);
            check_work(a.max_collisions, &slab, &cfg, wi0, &[], a.theta_i.len())?;
            for &ti in &a.theta_i {
                let (wi, _) = in_plane_directions(ti, 0.0, false);
                let t = simulate_totals(&slab, Incidence::Collimated(wi), &cfg)?;
                let what = format!("theta_i {ti}");
                text.push_str(&totals_row(&ti.to_string(), &what, &t, &cfg, rgb, &mut notes));
            }
        }
    } else {
        let Some(range) = &a.theta_o else {
            bail!("give --theta-o FROM:TO:STEP (BSDF values) or --totals");
        };
        if a.theta_i.is_empty() {
            bail!("--theta-o needs --theta-i LIST (degrees)");
        }
        let to = paperbsdf_io::angles::parse_angles(range, "--theta-o", MAX_VIEW_ANGLES)?;
        check_angles(&a.theta_i, "--theta-i", 0.0..90.0)?;
        check_angles(&to, "--theta-o", (Excluded(-90.0), Excluded(90.0)))?;
        let ti = a.theta_i[0];
        let (wi0, _) = in_plane_directions(ti, 0.0, false);
        check_work(a.max_collisions, &slab, &cfg, wi0, &view_dirs(ti, &to), a.theta_i.len())?;
        let cols = if rgb {
            "r,g,b,r_stderr,g_stderr,b_stderr"
        } else {
            "f,stderr"
        };
        text.push_str(&format!("kind,theta_i_deg,theta_o_deg,{cols}\n"));
        for &ti in &a.theta_i {
            // One set of walks per incident angle serves every viewing direction, R and T.
            let (wi, _) = in_plane_directions(ti, 0.0, false);
            let run = simulate_bsdf(&slab, wi, &view_dirs(ti, &to), &cfg)?;
            run_notes(
                &format!("theta_i {ti}"),
                &cfg,
                run.samples,
                run.truncated,
                run.worst_rel_stderr,
                run.target_reached,
                &mut notes,
            );
            for (k, (kind, _)) in [("R", false), ("T", true)].iter().enumerate() {
                for (j, &o) in to.iter().enumerate() {
                    text.push_str(&format!(
                        "{kind},{ti},{o},{}\n",
                        fmt_estimate(&run.f[k * to.len() + j], rgb)
                    ));
                }
            }
        }
    }
    for n in &notes {
        text.push_str(&format!("# {n}\n"));
    }
    crate::emit(a.out.as_deref(), &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(params: &str) -> SimulateArgs {
        SimulateArgs {
            params: params.to_string(),
            theta_i: vec![30.0],
            theta_o: Some("-60:60:60".into()),
            totals: false,
            diffuse: false,
            samples: Some(256),
            rel_stderr: None,
            max_samples: 1 << 20,
            batches: 8,
            seed: 3,
            max_collisions: DEFAULT_MAX_COLLISIONS,
            max_walk_collisions: paperbsdf_sim::walk::MAX_COLLISIONS_PER_WALK as u64,
            out: None,
        }
    }

    const P: &str = r#"{"d":0.05,"sigma_a":0.5,"sigma_s":[40,50,60],"g_f":0.8,"g_b":-0.3,"w_b":0.2,"eta_f":1.5,"eta_b":1.5,"m_f":0.3,"m_b":0.3,"dist_f":"ggx","dist_b":"beckmann"}"#;

    #[test]
    fn writes_rgb_table_atomically_and_reproducibly() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("sim.csv");
        let mut a = args(P);
        a.out = Some(out.to_str().unwrap().to_string());
        run(a).unwrap();
        let text = std::fs::read_to_string(&out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert!(
            lines[0].starts_with("# paperbsdf simulate") && lines[0].contains("\"sigma_s\":[40.0,50.0,60.0]"),
            "{}",
            lines[0]
        );
        assert_eq!(
            lines[1],
            "kind,theta_i_deg,theta_o_deg,r,g,b,r_stderr,g_stderr,b_stderr"
        );
        assert_eq!(lines.len(), 2 + 6);
        assert!(
            lines[2].starts_with("R,30,-60,") && lines[5].starts_with("T,30,-60,"),
            "{text}"
        );
        for l in &lines[2..] {
            let v: Vec<f64> = l.split(',').skip(3).map(|x| x.parse().unwrap()).collect();
            assert_eq!(v.len(), 6);
            assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0), "{l}");
            assert!(v[0] > 0.0, "{l}");
        }
        // Same seed, same output.
        let out2 = dir.path().join("sim2.csv");
        let mut a = args(P);
        a.out = Some(out2.to_str().unwrap().to_string());
        run(a).unwrap();
        assert_eq!(text, std::fs::read_to_string(&out2).unwrap());
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            2,
            "no temporary file left behind"
        );
    }

    #[test]
    fn totals_table() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("t.csv");
        let p = P.replace("[40,50,60]", "50");
        let mut a = args(&p);
        a.theta_o = None;
        a.totals = true;
        a.theta_i = vec![0.0, 60.0];
        a.out = Some(out.to_str().unwrap().to_string());
        run(a).unwrap();
        let text = std::fs::read_to_string(&out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[1], "theta_i_deg,R,R_stderr,T,T_stderr");
        assert_eq!(lines.len(), 4);
        for l in &lines[2..] {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            assert!(
                v[1] > 0.0 && v[3] > 0.0 && v[1] + v[3] <= 1.0 + 4.0 * (v[2] + v[4]),
                "{l}"
            );
        }
    }

    #[test]
    fn bad_input_is_a_clear_error() {
        let e = run(args(&P.replace("\"w_b\":0.2", "\"w_b\":1.2")))
            .unwrap_err()
            .to_string();
        assert!(e.contains("w_b") && e.contains("1.2") && e.contains("[0, 1]"), "{e}");
        let e = run(args("/nonexistent/params.json")).unwrap_err().to_string();
        assert!(e.contains("/nonexistent/params.json"), "{e}");
        let mut a = args(P);
        a.theta_i = vec![95.0];
        let e = run(a).unwrap_err().to_string();
        assert!(e.contains("--theta-i") && e.contains("95"), "{e}");
        let mut a = args(P);
        a.theta_o = Some("-90:90:10".into());
        let e = run(a).unwrap_err().to_string();
        assert!(e.contains("--theta-o") && e.contains("-90"), "{e}");
        let mut a = args(P);
        a.theta_o = Some("10:0:5".into());
        assert!(run(a).unwrap_err().to_string().contains("TO is below FROM"));
        let mut a = args(P);
        a.samples = None;
        a.rel_stderr = Some(1.5);
        assert!(run(a).unwrap_err().to_string().contains("--rel-stderr"));
        let mut a = args(P);
        a.batches = 1;
        assert!(run(a).unwrap_err().to_string().contains("--batches"));
    }
}
