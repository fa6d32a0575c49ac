//! Measurement files: the reader lives in [`paperbsdf_io::measurement`] (its
//! errors are [`paperbsdf_io::DataError`]); its items are re-exported here
//! under their old paths.

pub use paperbsdf_io::measurement::{parse_measurement, read_measurement, Kind, Measurement, Point};

/// The error of [`read_measurement`] and [`parse_measurement`]: the one error
/// type of data files, [`paperbsdf_io::DataError`] (this name is kept for old
/// code; new code should name `DataError`).
pub type MeasurementError = paperbsdf_io::DataError;

// The reader turns a `weight` column into a standard error with the objective's offset.
const _: () = assert!(paperbsdf_io::measurement::LOG_OFFSET == crate::objective::LOG_OFFSET);

#[cfg(test)]
mod tests {
    use super::*;

    /// A `weight` column reproduces the weight in the objective: weight 4 counts a
    /// point four times, weight 0 not at all (against the definition in `objective`).
    #[test]
    fn weight_column_is_the_objective_weight() {
        let m = parse_measurement(
            "kind,theta_i_deg,theta_o_deg,f,weight\nR,30,-30,1,4\nR,30,0,2,0\nR,30,10,0.5,1\n",
            "w.csv",
        )
        .unwrap();
        let w: Vec<f64> = m.points.iter().map(|p| crate::objective::weight(p, 0)).collect();
        assert!(
            (w[0] - 4.0).abs() < 1e-9 && w[1] == 0.0 && (w[2] - 1.0).abs() < 1e-9,
            "{w:?}"
        );
        let e = parse_measurement("kind,theta_i_deg,theta_o_deg,f,weight\nR,30,-30,1,-1\n", "w.csv").unwrap_err();
        assert!(
            e.to_string().contains("w.csv:2:5") && e.to_string().contains("negative weight"),
            "{e}"
        );
        let e = parse_measurement(
            "kind,theta_i_deg,theta_o_deg,f,weight,stderr\nR,30,-30,1,1,1\n",
            "w.csv",
        )
        .unwrap_err();
        assert!(e.to_string().contains("both"), "{e}");
    }
}
