//! Learning-rate schedules over the steps of a stage.

use burn::optim::LearningRate;
use burn::optim::lr_scheduler::{LrScheduler, LrSchedulerRecord};

/// The learning rate as a function of the step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Schedule {
    /// The same rate at every step.
    Constant(f64),
    /// A half cosine from `start` (step 0) to `end` (step `steps`).
    Cosine {
        /// Rate at step 0.
        start: f64,
        /// Rate at step `steps` (and the floor of the curve).
        end: f64,
        /// Length of the half cosine, in steps.
        steps: usize,
    },
}

impl Schedule {
    /// The rate at `step` (counted from 0).
    pub fn at(&self, step: usize) -> f64 {
        match *self {
            Schedule::Constant(lr) => lr,
            Schedule::Cosine { start, end, steps } => {
                let progress = (step as f64 / steps.max(1) as f64).min(1.0);
                end + (start - end) * 0.5 * (1.0 + (std::f64::consts::PI * progress).cos())
            }
        }
    }
}

/// A [`Schedule`] with its step counter, as burn's optimisers consume it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Scheduled {
    schedule: Schedule,
    next: usize,
}

impl From<Schedule> for Scheduled {
    fn from(schedule: Schedule) -> Self {
        Self { schedule, next: 0 }
    }
}

impl LrScheduler for Scheduled {
    fn step(&mut self) -> LearningRate {
        let lr = self.schedule.at(self.next);
        self.next += 1;
        lr
    }

    fn to_record(&self) -> LrSchedulerRecord {
        LrSchedulerRecord::new().with_scalar("next", self.next as f64)
    }

    fn load_record(&mut self, record: LrSchedulerRecord) {
        if let Some(next) = record.scalar::<f64>("next") {
            self.next = next as usize;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_runs_from_start_to_end_through_the_mean() {
        let s = Schedule::Cosine { start: 0.3, end: 0.01, steps: 100 };
        assert!((s.at(0) - 0.3).abs() < 1e-12);
        assert!((s.at(50) - 0.155).abs() < 1e-12);
        assert!((s.at(100) - 0.01).abs() < 1e-12);
        assert!((s.at(1000) - 0.01).abs() < 1e-12, "stays at the floor after the curve");
        let mut scheduled = Scheduled::from(s);
        let rates: Vec<f64> = (0..3).map(|_| scheduled.step()).collect();
        assert_eq!(rates, vec![s.at(0), s.at(1), s.at(2)]);
    }
}
