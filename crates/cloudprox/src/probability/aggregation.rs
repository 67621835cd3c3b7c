//! Aggregation of per-point probabilities into the pair's collision probability `P`.

use crate::Real;

/// A point's neighbourhood on its own surface: the point and its 6 nearest
/// (the surface probability's and the crossing test's).
pub(crate) const NEIGHBOURHOOD: usize = 7;

/// How the per-point probabilities `p_i` become the pair's `P`.
///
/// `Max`, `Union` and `Independent` (the paper's) are driven by the noisiest
/// single point; they differ in how much the other points add. `Surface` asks
/// where the sampled *surfaces* are, from each point's neighbourhood. Only the
/// points within the noise's reach of the other cloud count (see
/// [`crate::query::collide()`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Aggregation {
    /// `P = max_i q_i` with `q_i` the probability that the *surface* around point
    /// `i` lies on the wrong side: the margins `c_j f(x_j)` of the point and its 6
    /// nearest neighbours in its cloud are averaged, with the standard deviation
    /// of that mean (`sqrt(sum_j s_j^2) / 7`, `s_j = sqrt(grad^T Sigma_j grad)`),
    /// so `q_i = Phi(-mean / sd)` ([`surface_probability`]). A surface is located
    /// far better than one sample's noise; the worst single sample is not the
    /// surface. On the piano-in-room evaluation against exact ground truth
    /// (`cloudprox reproduce`) it decides more poses, and more of them correctly,
    /// than `Max`. Where two surfaces cross, the neighbourhood means cancel (two
    /// spheres overlapping by half at 1 mm noise read P = 0.08), so each point's
    /// value is the larger of `q_i` and the probability that the surfaces cross
    /// there ([`crate::probability::crossing_probabilities`]). **Not the
    /// default**: a deep crossing seen by sparse or noisy points can still pass
    /// (3-6% of the poses 3-8 sigma deep in the reproduction read `free`, where
    /// `Max` reads none).
    Surface,
    /// `P = max_i p_i`: the probability that the single most doubtful point is on
    /// the wrong side. What the first implementation of the method (FCL) reported.
    /// The default.
    #[default]
    Max,
    /// `P = min(1, sum_i p_i)`: the union (Boole) bound on the probability that any
    /// point is on the wrong side, valid whatever the correlation between points. A
    /// conservative upper bound; grows with the number of near points.
    Union,
    /// `P = 1 - prod_i (1 - p_i)`: the probability that any point is on the wrong
    /// side if the points' noise is independent. Between `Max` and `Union`.
    Independent,
}

crate::names::named_options!(Aggregation, "aggregation", {
    Surface => "surface",
    Max => "max",
    Union => "union",
    Independent => "independent",
});

impl Aggregation {
    /// Aggregates `probabilities` (an empty slice gives 0); for `Surface`, the
    /// surface probabilities `q_i` (their maximum).
    pub fn aggregate<I: IntoIterator<Item = Real>>(self, probabilities: I) -> Real {
        let it = probabilities.into_iter();
        match self {
            Aggregation::Max | Aggregation::Surface => it.fold(0.0, Real::max),
            Aggregation::Union => it.sum::<Real>().min(1.0),
            Aggregation::Independent => {
                // sum of log(1 - p), with ln_1p for accuracy at small p.
                let log_free: Real = it.map(|p| (-p).ln_1p()).sum();
                -log_free.exp_m1()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_three_aggregates() {
        let p = [0.1, 0.2, 0.05];
        assert_eq!(Aggregation::Max.aggregate(p), 0.2);
        assert!((Aggregation::Union.aggregate(p) - 0.35).abs() < 1e-15);
        let ind = 1.0 - 0.9 * 0.8 * 0.95;
        assert!((Aggregation::Independent.aggregate(p) - ind).abs() < 1e-15);
        assert_eq!(Aggregation::Union.aggregate([0.7, 0.8]), 1.0);
        assert_eq!(Aggregation::Independent.aggregate([1.0, 0.3]), 1.0);
        assert_eq!(Aggregation::Surface.aggregate(p), 0.2);
        for a in [
            Aggregation::Surface,
            Aggregation::Max,
            Aggregation::Union,
            Aggregation::Independent,
        ] {
            assert_eq!(a.aggregate(std::iter::empty()), 0.0);
            assert_eq!(Aggregation::from_name(a.name()), Some(a));
            // max <= independent <= union (surface aggregates other inputs)
            assert!(Aggregation::Max.aggregate(p) <= a.aggregate(p) + 1e-15);
            assert!(a.aggregate(p) <= Aggregation::Union.aggregate(p) + 1e-15);
        }
    }
}

/// The probability that the surface around a point lies on the wrong side, from
/// the margins `c_j f(x_j)` and standard deviations `s_j` along the gradient of
/// the point and its neighbours: `Phi(-mean(m) / (sqrt(sum s_j^2) / n))`, the
/// noise of the points taken as independent. Exact (0 or 1) when every `s_j` is 0.
pub fn surface_probability(margins: &[Real], stds: &[Real]) -> Real {
    let n = margins.len() as Real;
    if margins.is_empty() {
        return 0.0;
    }
    let mean = margins.iter().sum::<Real>() / n;
    let sd = stds.iter().map(|s| s * s).sum::<Real>().sqrt() / n;
    crate::probability::gaussian::wrong_side(mean, sd)
}

#[cfg(test)]
mod surface_tests {
    use super::*;
    use crate::probability::normal_cdf;

    #[test]
    fn surface_probability_shrinks_with_the_neighbourhood() {
        // Seven points all 1 sigma on the right side: the mean is known to
        // sigma / sqrt(7), so the surface is sqrt(7) sigma clear.
        let p = surface_probability(&[1.0; 7], &[1.0; 7]);
        assert!((p - normal_cdf(-(7f64).sqrt())).abs() < 1e-15);
        // One point alone is Eq. 3.
        assert!((surface_probability(&[0.5], &[2.0]) - normal_cdf(-0.25)).abs() < 1e-15);
        assert_eq!(surface_probability(&[0.1, 0.2], &[0.0, 0.0]), 0.0);
        assert_eq!(surface_probability(&[-0.1, 0.0], &[0.0, 0.0]), 1.0);
        assert_eq!(surface_probability(&[], &[]), 0.0);
    }
}
