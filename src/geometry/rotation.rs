//! Rigid transforms as burn tensor programs, batched over N (one pose per point or per time), so
//! that the motion models are differentiable end to end.

use burn::tensor::Tensor;

/// Below this squared angle (rad²) the Rodrigues coefficients come from their Taylor series:
/// `sin θ / θ` and `(1 - cos θ) / θ²` lose all precision in f32 near 0, and their exact forms
/// have no finite derivative at 0. The series to θ⁶ is exact to ~1e-10 here.
const SERIES_BELOW: f32 = 1e-2;

/// A batch of N rigid transforms `P -> R P + T`.
#[derive(Debug, Clone)]
pub struct PoseBatch {
    /// Rotations, `[N, 3, 3]`.
    pub rotation: Tensor<3>,
    /// Translations, metres, `[N, 3]`.
    pub translation: Tensor<2>,
}

/// The rotations `R = exp([r]×)` of the rotation vectors `r` (`[N, 3]`, radians), by Rodrigues'
/// formula `R = I + A [r]× + B [r]×²` with `A = sin θ / θ`, `B = (1 - cos θ) / θ²`; `[N, 3, 3]`.
pub fn rotation_matrices(r: Tensor<2>) -> Tensor<3> {
    let n = r.dims()[0];
    let part = |i: usize| r.clone().slice([0..n, i..i + 1]).reshape([n]);
    let (x, y, z) = (part(0), part(1), part(2));
    let theta2 = x.clone() * x.clone() + y.clone() * y.clone() + z.clone() * z.clone();
    let small = theta2.clone().lower_elem(SERIES_BELOW);
    // Series branch.
    let t2 = theta2.clone();
    let t4 = t2.clone() * t2.clone();
    let t6 = t4.clone() * t2.clone();
    let a_series = (t2.clone() / -6.0) + (t4.clone() / 120.0) - (t6.clone() / 5040.0) + 1.0;
    let b_series = (t2 / -24.0) + (t4 / 720.0) - (t6 / 40320.0) + 0.5;
    // Exact branch on an angle kept away from 0, so that its unused derivative stays finite.
    let theta = theta2.clone().clamp_min(SERIES_BELOW).sqrt();
    let a_exact = theta.clone().sin() / theta.clone();
    let b_exact = (theta.clone().cos().neg() + 1.0) / (theta.clone() * theta);
    let a = a_exact.mask_where(small.clone(), a_series);
    let b = b_exact.mask_where(small, b_series);
    // R_ij = δ_ij (1 - B θ²) + A [r]×_ij + B r_i r_j.
    let diag = (b.clone() * theta2).neg() + 1.0;
    let rr = |p: &Tensor<1>, q: &Tensor<1>| b.clone() * p.clone() * q.clone();
    let ax = |p: &Tensor<1>| a.clone() * p.clone();
    let entries = vec![
        diag.clone() + rr(&x, &x),
        rr(&x, &y) - ax(&z),
        rr(&x, &z) + ax(&y),
        rr(&y, &x) + ax(&z),
        diag.clone() + rr(&y, &y),
        rr(&y, &z) - ax(&x),
        rr(&z, &x) - ax(&y),
        rr(&z, &y) + ax(&x),
        diag + rr(&z, &z),
    ];
    Tensor::stack::<2>(entries, 1).reshape([n, 3, 3])
}

/// `R p` for a batch of rotations `[N, 3, 3]` and points `[N, 3]` (or one rotation `[1, 3, 3]`
/// broadcast over the points).
pub fn rotate(rotation: &Tensor<3>, points: Tensor<2>) -> Tensor<2> {
    let n = points.dims()[0];
    (rotation.clone() * points.unsqueeze_dim::<3>(1)).sum_dim(2).reshape([n, 3])
}

/// `Rᵀ p`, the inverse rotation.
pub fn rotate_inverse(rotation: &Tensor<3>, points: Tensor<2>) -> Tensor<2> {
    let n = points.dims()[0];
    (rotation.clone() * points.unsqueeze_dim::<3>(2)).sum_dim(1).reshape([n, 3])
}

impl PoseBatch {
    /// `R P + T`.
    pub fn apply(&self, points: Tensor<2>) -> Tensor<2> {
        rotate(&self.rotation, points) + self.translation.clone()
    }

    /// `Rᵀ (P - T)`: the inverse transform.
    pub fn apply_inverse(&self, points: Tensor<2>) -> Tensor<2> {
        rotate_inverse(&self.rotation, points - self.translation.clone())
    }
}

/// Batched products `a b` of 3x3 matrices (`[N, 3, 3]` each), as three broadcast
/// multiply-adds: for matrices this small that is cheaper than a batched matmul on flex.
pub fn compose(a: Tensor<3>, b: Tensor<3>) -> Tensor<3> {
    let n = a.dims()[0];
    (0..3)
        .map(|k| a.clone().slice([0..n, 0..3, k..k + 1]) * b.clone().slice([0..n, k..k + 1, 0..3]))
        .reduce(|x, y| x + y)
        .expect("three terms")
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::{Device, TensorData};
    use nalgebra::{Rotation3, Vector3};

    use crate::device::host_values as values;

    #[test]
    fn compose_is_the_batched_matrix_product() {
        let device = Device::flex();
        let entries = |seed: f32| (0..18).map(|i| ((i as f32 + seed) * 0.37).sin()).collect::<Vec<f32>>();
        let a = Tensor::<3>::from_data(TensorData::new(entries(1.0), [2, 3, 3]), &device);
        let b = Tensor::<3>::from_data(TensorData::new(entries(5.0), [2, 3, 3]), &device);
        let (got, expected) = (values(compose(a.clone(), b.clone())), values(a.matmul(b)));
        assert!(got.iter().zip(&expected).all(|(g, e)| (g - e).abs() < 1e-6), "{got:?} vs {expected:?}");
    }

    #[test]
    fn matches_nalgebra_on_both_branches() {
        let device = Device::flex();
        let vecs = [[0.0, 0.0, 0.0], [1e-4, -2e-4, 3e-5], [0.03, -0.05, 0.02], [0.4, 0.1, -0.7], [2.0, -1.0, 0.5]];
        let flat: Vec<f32> = vecs.iter().flatten().map(|&x| x as f32).collect();
        let r = values(rotation_matrices(Tensor::from_data(TensorData::new(flat, [vecs.len(), 3]), &device)));
        for (i, v) in vecs.iter().enumerate() {
            let m = Rotation3::new(Vector3::from(*v));
            for a in 0..3 {
                for b in 0..3 {
                    let got = r[i * 9 + a * 3 + b] as f64;
                    assert!((got - m[(a, b)]).abs() < 2e-6, "vector {v:?} entry ({a},{b}): {got} vs {}", m[(a, b)]);
                }
            }
        }
    }

    #[test]
    fn gradient_at_zero_is_finite_and_right() {
        // d(R(r) p)/dr at r = 0 is -[p]×: for p = (1, 0, 0), d(R p)_y/d r_z = 1.
        let device = Device::flex().autodiff();
        let r = Tensor::<2>::zeros([1, 3], &device).require_grad();
        let p = Tensor::<2>::from_data(TensorData::new(vec![1.0f32, 0.0, 0.0], [1, 3]), &device);
        let out = rotate(&rotation_matrices(r.clone()), p).slice([0..1, 1..2]).sum();
        let grad = values(r.grad(&out.backward()).unwrap());
        assert!((grad[0]).abs() < 1e-6 && (grad[1]).abs() < 1e-6 && (grad[2] - 1.0).abs() < 1e-6, "{grad:?}");
    }
}
