//! Gradients of a loss taken part by part: each part backpropagated on its own graph, the
//! parts' gradients summed with weights. A loss that is a sum over views then never holds more
//! than one view's graph per core, and the views can be evaluated on the cores in parallel.

use super::MeanLoss;
use burn::module::{Module, ModuleVisitor, Param};
use burn::optim::GradientsParams;
use burn::tensor::{Device, Tensor};
use rayon::prelude::*;

/// The gradients of `loss` with respect to `module`'s parameters (those that require them).
pub fn gradients_of<M: Module>(loss: Tensor<1>, module: &M) -> GradientsParams {
    GradientsParams::from_grads(loss.backward(), module)
}

/// The mean of the terms that `part(module, i)` collects over the parts `i` in `0..parts` (the
/// views a step compares, say), and its gradients as weighted parts for [`weighted_sum`]; `None`
/// where no part collects a term. Each part is evaluated on the cores in parallel, on its own
/// graph from the parameters up (a fork of `module` on `device`, with the same parameter ids),
/// which is freed once its gradients are read: as many parts' graphs live at once as there are
/// cores. The parts come back in their order, so the sums do not depend on how the parts are
/// spread over the cores.
pub fn mean_over_parts<M: Module + Sync>(
    module: &M,
    parts: usize,
    device: &Device,
    part: impl Fn(&M, usize) -> MeanLoss + Sync,
) -> Option<(f32, Vec<(GradientsParams, f32)>)> {
    let evaluated: Vec<(usize, Option<(f32, GradientsParams)>)> = (0..parts)
        .into_par_iter()
        .map(|i| {
            // Leaves of this part's graph alone: graphs that share a node are merged into one,
            // and burn's autodiff then deadlocks when one core builds on it while another reads
            // its gradients back.
            let own = module.clone().fork(device);
            let terms = part(&own, i);
            let count = terms.count();
            (count, terms.sum().map(|sum| (sum.clone().into_scalar::<f32>(), gradients_of(sum, &own))))
        })
        .collect();
    let count: usize = evaluated.iter().map(|(count, _)| count).sum();
    if count == 0 {
        return None;
    }
    let (sum, grads) = evaluated.into_iter().filter_map(|(_, sum)| sum).fold((0.0, Vec::new()), |(total, mut grads), (value, g)| {
        grads.push((g, 1.0 / count as f32));
        (total + value, grads)
    });
    Some((sum / count as f32, grads))
}

/// `Σ wᵢ gᵢ` over the parts `(gᵢ, wᵢ)`, parameter by parameter of `module`, summed in the parts'
/// order; a parameter no part has a gradient for has none in the sum.
pub fn weighted_sum<M: Module>(module: &M, parts: Vec<(GradientsParams, f32)>) -> GradientsParams {
    let mut visitor = WeightedSum { parts, sum: GradientsParams::new() };
    module.visit(&mut visitor);
    visitor.sum
}

struct WeightedSum {
    parts: Vec<(GradientsParams, f32)>,
    sum: GradientsParams,
}

impl ModuleVisitor for WeightedSum {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        let weighted =
            self.parts.iter_mut().filter_map(|(grads, w)| grads.remove::<D>(param.id).map(|g| if *w == 1.0 { g } else { g * *w }));
        if let Some(sum) = weighted.reduce(|a, b| a + b) {
            self.sum.register(param.id, sum);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::host_values;
    use burn::module::Param;
    use burn::tensor::{Device, TensorData};

    #[derive(Module, Debug)]
    struct Pair {
        a: Param<Tensor<1>>,
        b: Param<Tensor<1>>,
    }

    fn pair(device: &Device) -> Pair {
        let param = |v: Vec<f32>| Param::from_tensor(Tensor::<1>::from_data(TensorData::new(v, [2]), device));
        Pair { a: param(vec![1.0, -2.0]), b: param(vec![0.5, 3.0]) }
    }

    /// `Σ a² + 3 Σ a b` in two parts, and whole.
    fn parts(m: &Pair) -> (Tensor<1>, Tensor<1>) {
        let (a, b) = (m.a.val(), m.b.val());
        ((a.clone() * a.clone()).sum(), (a * b).sum() * 3.0)
    }

    #[test]
    fn parts_summed_with_weights_give_the_gradient_of_the_weighted_sum() {
        let device = Device::flex().autodiff();
        let m = pair(&device);
        let (first, second) = parts(&m);
        let summed = weighted_sum(&m, vec![(gradients_of(first, &m), 0.5), (gradients_of(second, &m), 2.0)]);
        let (first, second) = parts(&m);
        let mut whole = gradients_of(first * 0.5 + second * 2.0, &m);
        for id in [m.a.id, m.b.id] {
            let (got, want) = (host_values(summed.get::<1>(id).unwrap()), host_values(whole.remove::<1>(id).unwrap()));
            assert_eq!(got.len(), 2);
            got.iter().zip(&want).for_each(|(g, w)| assert!((g - w).abs() < 1e-6, "{got:?} against {want:?}"));
        }
        // d/da: a + 6 b; d/db: 6 a.
        assert_eq!(host_values(summed.get::<1>(m.a.id).unwrap()), vec![4.0, 16.0]);
        assert_eq!(host_values(summed.get::<1>(m.b.id).unwrap()), vec![6.0, -12.0]);
    }

    #[test]
    fn the_mean_over_parts_and_its_gradient_are_those_of_the_mean_of_all_their_terms() {
        let device = Device::flex().autodiff();
        let m = pair(&device);
        // Part i collects i + 1 terms, the k-th Σ (k + 1) a b: six terms in all, unevenly spread.
        let term = |m: &Pair, k: usize| (m.a.val() * m.b.val() * (k as f32 + 1.0)).sum();
        let part = |m: &Pair, i: usize| {
            let mut terms = MeanLoss::default();
            (0..=i).for_each(|k| terms.add(Some(term(m, k))));
            terms
        };
        let (value, parts) = mean_over_parts(&m, 3, &device, part).expect("terms");
        let summed = weighted_sum(&m, parts);
        let mut all = MeanLoss::default();
        (0..3).for_each(|i| (0..=i).for_each(|k| all.add(Some(term(&m, k)))));
        let whole = all.mean().unwrap();
        assert!((value - whole.clone().into_scalar::<f32>()).abs() < 1e-5, "{value}");
        let mut whole = gradients_of(whole, &m);
        for id in [m.a.id, m.b.id] {
            let (got, want) = (host_values(summed.get::<1>(id).unwrap()), host_values(whole.remove::<1>(id).unwrap()));
            got.iter().zip(&want).for_each(|(g, w)| assert!((g - w).abs() < 1e-5, "{got:?} against {want:?}"));
        }
        assert!(mean_over_parts(&m, 3, &device, |_, _| MeanLoss::default()).is_none(), "no terms, no loss");
    }

    #[test]
    fn a_parameter_held_out_of_every_part_has_no_gradient() {
        let device = Device::flex().autodiff();
        let m = pair(&device);
        let loss = |m: &Pair| (m.a.val() * m.a.val()).sum();
        let summed = weighted_sum(&m, vec![(gradients_of(loss(&m), &m), 1.0), (gradients_of(loss(&m), &m), 1.0)]);
        assert_eq!(host_values(summed.get::<1>(m.a.id).unwrap()), vec![4.0, -8.0]);
        assert!(summed.get::<1>(m.b.id).is_none());
    }
}
