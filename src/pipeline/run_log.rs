//! What a run reports as it goes: one line per stage, with the figures it quotes (a loss curve's
//! two ends, a fitted motion).

use crate::model::motion::MotionModel;

/// Which stages a run carried out, for the user and the logs.
#[derive(Debug, Clone, Default)]
pub struct RunLog {
    /// One line per stage: what ran, with its figures, or why it did not.
    pub lines: Vec<String>,
    /// Whether each line is also printed to standard output as it is added.
    echo: bool,
}

impl RunLog {
    /// A log that prints each line as it comes, so that a long run shows where it is even with
    /// its output going to a file (the progress bars draw only on a terminal).
    pub fn printing() -> Self {
        Self { lines: Vec::new(), echo: true }
    }

    /// Adds a line (and prints it, for a [`RunLog::printing`] log).
    pub fn push(&mut self, line: impl Into<String>) {
        let line = line.into();
        if self.echo {
            outln!("{line}");
        }
        self.lines.push(line);
    }
}

/// The mean loss of a fit's first and last `round` steps (NaN for an empty curve). Each step
/// scores some bands of rows only, so one step's loss against another's compares different
/// rows: a stage-1 fit at 512 px read 0.044 -> 0.050 (its top band against its fourth) while
/// every band's loss fell 2-3x, the round's mean 0.093 -> 0.040. A round of steps covers the
/// image.
pub(super) fn curve_ends(curve: &[f32], round: usize) -> (f32, f32) {
    let n = round.max(1).min(curve.len());
    let mean = |steps: &[f32]| if steps.is_empty() { f32::NAN } else { steps.iter().sum::<f32>() / steps.len() as f32 };
    (mean(&curve[..n]), mean(&curve[curve.len() - n..]))
}

/// A motion's parameters as `motion.toml` names them, five significant digits each, for the log:
/// `omega_rad_s [6.2191e-2, 0, 0], velocity_m_s [0, -2.4877e-1, 0]`.
pub(super) fn estimate_line(model: &dyn MotionModel, parameters: &[f64]) -> String {
    let number = |x: f64| if x == 0.0 { "0".to_string() } else { format!("{x:.4e}") };
    model
        .record(parameters)
        .groups()
        .into_iter()
        .map(|(name, values)| format!("{name} [{}]", values.into_iter().map(number).collect::<Vec<_>>().join(", ")))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::curve_ends;
    use crate::render::row_bands;

    #[test]
    fn a_round_of_bands_compares_the_whole_image_at_both_ends() {
        // Four bands taken in turn, each loss falling by half over three rounds, the last band
        // the hardest: its last step reads higher than the first band's first step.
        let per_band = [0.1_f32, 0.2, 0.3, 0.8];
        let curve: Vec<f32> = (0..12).map(|step| per_band[step % 4] * 0.5_f32.powi((step / 4) as i32)).collect();
        assert!(curve[11] > curve[0]);
        let (first, last) = curve_ends(&curve, row_bands(0..64, 16).len());
        assert!((first - 0.35).abs() < 1e-6 && (last - 0.0875).abs() < 1e-6, "{first} -> {last}");
        // A curve shorter than a round is compared with itself; an empty one gives NaN.
        let (a, b) = curve_ends(&curve[..3], 4);
        assert!(a == b && (a - 0.2).abs() < 1e-6, "{a} -> {b}");
        assert!(curve_ends(&[], 4).0.is_nan());
        assert_eq!(row_bands(0..100, 16).len(), 7);
        assert_eq!(row_bands(0..100, 0).len(), 100);
    }
}
