//! Aggregation of per-point probabilities into the pair's collision probability `P`.

use crate::Real;

/// How the per-point probabilities `p_i` become the pair's `P`.
///
/// All three are driven by the noisiest single point; they differ in how much the
/// other points add.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Aggregation {
    /// `P = max_i p_i`: the probability that the single most doubtful point is on
    /// the wrong side. What the first implementation of the method (FCL) reported.
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

impl Aggregation {
    /// Aggregates `probabilities` (an empty slice gives 0).
    pub fn aggregate<I: IntoIterator<Item = Real>>(self, probabilities: I) -> Real {
        let it = probabilities.into_iter();
        match self {
            Aggregation::Max => it.fold(0.0, Real::max),
            Aggregation::Union => it.sum::<Real>().min(1.0),
            Aggregation::Independent => {
                // sum of log(1 - p), with ln_1p for accuracy at small p.
                let log_free: Real = it.map(|p| (-p).ln_1p()).sum();
                -log_free.exp_m1()
            }
        }
    }

    /// Parses `"max"`, `"union"` or `"independent"`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "max" => Some(Aggregation::Max),
            "union" => Some(Aggregation::Union),
            "independent" => Some(Aggregation::Independent),
            _ => None,
        }
    }

    /// The lowercase name, as [`Aggregation::from_name`] reads it.
    pub fn name(self) -> &'static str {
        match self {
            Aggregation::Max => "max",
            Aggregation::Union => "union",
            Aggregation::Independent => "independent",
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
        for a in [
            Aggregation::Max,
            Aggregation::Union,
            Aggregation::Independent,
        ] {
            assert_eq!(a.aggregate(std::iter::empty()), 0.0);
            assert_eq!(Aggregation::from_name(a.name()), Some(a));
            // max <= independent <= union
            assert!(Aggregation::Max.aggregate(p) <= a.aggregate(p) + 1e-15);
            assert!(a.aggregate(p) <= Aggregation::Union.aggregate(p) + 1e-15);
        }
    }
}
