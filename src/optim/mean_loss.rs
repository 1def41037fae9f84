//! The mean (or sum) of the loss terms a step collects (one per band and view).

use burn::tensor::Tensor;

/// Accumulates per-band losses and averages them.
#[derive(Debug, Default)]
pub struct MeanLoss {
    sum: Option<Tensor<1>>,
    count: usize,
}

impl MeanLoss {
    /// Adds a term; `None` (no term applied) is skipped.
    pub fn add(&mut self, term: Option<Tensor<1>>) {
        if let Some(term) = term {
            self.sum = Some(match self.sum.take() {
                Some(sum) => sum + term,
                None => term,
            });
            self.count += 1;
        }
    }

    /// Number of terms added.
    pub fn count(&self) -> usize {
        self.count
    }

    /// The sum of the terms added, or `None` when none was.
    pub fn sum(self) -> Option<Tensor<1>> {
        self.sum
    }

    /// The mean of the terms added, or `None` when none was.
    pub fn mean(self) -> Option<Tensor<1>> {
        self.sum.map(|s| s / self.count as f32)
    }
}
