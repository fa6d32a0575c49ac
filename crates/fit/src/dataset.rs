//! One or more measurement files fitted together: their points, channel
//! count and thickness (from the command line or the files' headers).

use crate::error::FitError;
use crate::measurement::{read_measurement, Point};

/// Points of one or more measurement files.
#[derive(Clone, Debug)]
pub struct Dataset {
    /// The files.
    pub origins: Vec<String>,
    /// All points, file by file.
    pub points: Vec<Point>,
    /// 3 for RGB data, else 1.
    pub channels: usize,
    /// Thickness in mm: the given one, else the files' headers (which must agree).
    pub thickness: Option<f64>,
    /// The `# params:` header of the first file that has one.
    pub params_header: Option<serde_json::Value>,
}

/// Reads `paths`; `thickness` (mm) overrides the headers' thickness.
pub fn load_dataset(paths: &[String], thickness: Option<f64>) -> Result<Dataset, FitError> {
    if paths.is_empty() {
        return Err(FitError::NoFiles);
    }
    if let Some(d) = thickness {
        if !(d > 0.0 && d.is_finite()) {
            return Err(FitError::ThicknessFlag(d));
        }
    }
    let mut ds = Dataset {
        origins: vec![],
        points: vec![],
        channels: 0,
        thickness,
        params_header: None,
    };
    let mut header_d: Option<(f64, String)> = None;
    for p in paths {
        let m = read_measurement(p)?;
        let ch = if m.is_rgb { 3 } else { 1 };
        if ds.channels != 0 && ds.channels != ch {
            return Err(FitError::ChannelMismatch {
                file: p.clone(),
                channels: ch,
                first: ds.origins[0].clone(),
                first_channels: ds.channels,
            });
        }
        ds.channels = ch;
        if let Some(d) = m.thickness {
            match &header_d {
                Some((d0, f0)) if (d0 - d).abs() > 1e-12 && thickness.is_none() => {
                    return Err(FitError::ThicknessMismatch {
                        file: p.clone(),
                        d,
                        first: f0.clone(),
                        first_d: *d0,
                    });
                }
                None => header_d = Some((d, p.clone())),
                _ => {}
            }
        }
        if ds.params_header.is_none() {
            ds.params_header = m.params_header.clone();
        }
        ds.origins.push(p.clone());
        ds.points.extend(m.points);
    }
    if ds.thickness.is_none() {
        ds.thickness = header_d.map(|h| h.0);
    }
    Ok(ds)
}
