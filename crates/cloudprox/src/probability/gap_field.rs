//! The gap between two sampled surfaces over one contact, as a smooth field
//! fitted to the facing pairs' readings ([`field_probability`]).

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use crate::element::height_row;
use crate::math::{Matrix3, Point3, Vector3};
use crate::probability::gaussian::wrong_side;
use crate::Real;

/// One facing pair's reading of the gap at a place of the contact.
#[derive(Debug, Clone, Copy)]
pub(crate) struct GapSample {
    /// Where the pair lies (any frame shared by the contact's readings).
    pub at: Point3,
    /// The gap read there.
    pub gap: Real,
    /// Its standard deviation.
    pub std: Real,
}

/// How far (in standard deviations of its own reading, scaled by the fit's
/// spread) a reading must lie below the fitted field to be read on its own:
/// a place where the surfaces come closer than the field describes.
const BELOW_FIELD_SDS: Real = 3.5;

/// How many of its own standard deviations a reading must read the two
/// surfaces crossed by to be read on its own: a crossing that no reading of
/// a contact at touching reads by chance (`Phi(-4)` is 3e-5 a reading), and
/// that a smooth field may not follow (at a deep crossing only the pairs near
/// where the surfaces cross are within reach, and read gaps of both signs).
const CROSSED_SDS: Real = 4.0;

/// The selection criterion's cost per term of the field (2: Akaike's).
const CRITERION_PER_TERM: Real = 2.0;

/// How many of its own standard deviations the field's `chi^2` must exceed
/// its degrees of freedom by for the readings' excess spread to count as the
/// gap's own variation about the field ([`Averaged::misfit_variance`]): 2, a
/// one-sided test at about 2 %.
const MISFIT_SDS: Real = 2.0;

/// How many of its standard deviations a reading's gap must lie above the
/// least of the readings' upper bounds (each `g + (2 + e_n) s`, see
/// [`contending`]) for it to be left out of a misfitting field: 2.
const CONTENDING_SDS: Real = 2.0;

/// Huber's tuning constant of the robust fit (in scaled standard deviations).
const HUBER: Real = 2.0;

/// The probability that the two surfaces cross over a contact, from its
/// readings pooled into a smooth gap field; `None` when they cannot be fitted
/// (fewer than three, or one without a positive finite standard deviation).
///
/// The gap over the contact is fitted by weighted least squares as a
/// constant, a plane and a quadric in the contact's two widest directions,
/// robustly (Huber weights, so that a few readings off the field do not move
/// it), each fit's covariance scaled by its reduced `chi^2` where it exceeds 1
/// (readings spread more than their stated deviations), and the three are
/// averaged with their Akaike weights ([`Averaged`]; a flat contact reads
/// mostly as a constant, two spheres as a quadric). Where the readings
/// spread about the field significantly more than their stated deviations
/// ([`MISFIT_SDS`]), the excess is the gap's own variation about the smooth
/// field (a corner pressed towards a face rises as a cone, which no quadric
/// follows): a random effect of variance `tau^2` per place, estimated by the
/// method of moments, so that at a reading's place the gap is the field
/// shrunk towards the reading (`k = tau^2 / (tau^2 + s^2)`; variance `(1 -
/// k)^2 v + k s^2`), and where no reading lies the field's variance gains
/// `tau^2`. `P` is the largest `Phi(-g / s)` of the field where the quadric
/// is lowest and at the readings' places, and of every reading lying more than
/// [`BELOW_FIELD_SDS`] below the field or reading a crossing of more than
/// [`CROSSED_SDS`] (where the surfaces truly come closer than a smooth field
/// says, it reads the contact).
///
/// The pooled field answers the question the readings share: the most
/// critical of many noisy readings of one flat contact reads the minimum of
/// their noise, not the gap (at touching it reads `P` near 1, where the
/// field reads 1/2).
pub(crate) fn field_probability(samples: &[GapSample]) -> Option<Real> {
    let terms = field_terms(samples)?;
    Some(
        terms
            .iter()
            .map(|t| wrong_side(t.gap, t.std))
            .fold(0.0, Real::max),
    )
}

/// The gap and standard deviation at one place the pooled field is read
/// ([`field_terms`]), and the reading nearest that place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FieldTerm {
    /// The gap there.
    pub gap: Real,
    /// Its standard deviation.
    pub std: Real,
    /// The index of the sample nearest the place (the sample itself where
    /// the term is a sample's place or the sample read on its own).
    pub sample: usize,
}

/// The term of the pooled field with the smallest gap ([`field_terms`]):
/// where the fitted gap field (or a reading read on its own) says the two
/// surfaces come closest; its `Phi(-gap / std)` is one of the terms whose
/// largest [`field_probability`] is. `None` as [`field_probability`].
pub(crate) fn field_minimum(samples: &[GapSample]) -> Option<FieldTerm> {
    field_terms(samples)?
        .into_iter()
        .min_by(|x, y| x.gap.total_cmp(&y.gap))
}

/// Every place [`field_probability`] reads: the fitted field where a
/// quadric field is lowest, at each reading's place, and each reading that
/// is read on its own; `None` without a fit.
///
/// Where no smooth field describes all the readings ([`MISFIT_SDS`]), the
/// field is fitted again over the readings that contend for the closest
/// place ([`contending`]): a gap that jumps (a piano's underside over a
/// table's top and over its side faces) is no smooth field, and its part
/// far above the closest place says nothing of whether the surfaces cross.
fn field_terms(samples: &[GapSample]) -> Option<Vec<FieldTerm>> {
    if samples.len() < 3 || samples.iter().any(|s| !(s.std > 0.0 && s.std.is_finite())) {
        return None;
    }
    let (terms, misfit) = fitted_terms(samples)?;
    if !misfit {
        return Some(terms);
    }
    let kept = contending(samples);
    if kept.len() == samples.len() {
        return Some(terms);
    }
    let own: Vec<GapSample> = kept.iter().map(|&i| samples[i]).collect();
    let mut narrowed = if own.len() < 3 {
        // One or two places can be the closest: each is read on its own.
        (0..own.len())
            .map(|i| FieldTerm {
                gap: own[i].gap,
                std: own[i].std,
                sample: i,
            })
            .collect()
    } else {
        match fitted_terms(&own) {
            Some((t, _)) => t,
            None => return Some(terms),
        }
    };
    for t in &mut narrowed {
        t.sample = kept[t.sample];
    }
    Some(narrowed)
}

/// The readings that may lie where the two surfaces come closest: those
/// whose gap, less [`CONTENDING_SDS`] of its standard deviations, is no
/// larger than the least upper bound `min_j (g_j + (CONTENDING_SDS + e_n)
/// s_j)`, with `e_n = Phi^-1(1 - 1/(n + 1))` (a reading above it is, with
/// confidence, not at the closest place: a table's side faces below a
/// piano's underside resting on its top). Their indices, in order.
fn contending(samples: &[GapSample]) -> Vec<usize> {
    // The least of n readings of one gap lies about Phi^-1(1 - 1/(n + 1))
    // of their deviations below it: the ceiling is read from where the
    // lowest reading's gap may be, not from its noise.
    let n = samples.len() as Real;
    let extreme = -crate::probability::normal_quantile(1.0 / (n + 1.0));
    let ceiling = samples
        .iter()
        .map(|s| s.gap + (CONTENDING_SDS + extreme) * s.std)
        .fold(Real::INFINITY, Real::min);
    (0..samples.len())
        .filter(|&i| samples[i].gap - CONTENDING_SDS * samples[i].std <= ceiling)
        .collect()
}

/// [`field_terms`] of one smooth field over all of `samples` (at least
/// three, each with a positive finite deviation), and whether they spread
/// about it significantly more than their deviations ([`MISFIT_SDS`]).
fn fitted_terms(samples: &[GapSample]) -> Option<(Vec<FieldTerm>, bool)> {
    let n = samples.len();
    let coords = contact_coordinates(samples);
    let r = DVector::from_iterator(n, samples.iter().map(|s| s.gap));
    let w0 = DVector::from_iterator(n, samples.iter().map(|s| 1.0 / (s.std * s.std)));
    let field = Averaged::new(
        [1usize, 3, 6]
            .into_iter()
            .filter(|&k| n >= k + 2)
            .filter_map(|k| Fit::robust(&design(&coords, k), &r, &w0))
            .collect(),
    )?;
    let tau2 = field.misfit_variance(&w0);
    let at = |u: [Real; 2], sample: usize| {
        let (gap, var) = field.at(u);
        FieldTerm {
            gap,
            std: (var + tau2).max(0.0).sqrt(),
            sample,
        }
    };
    // At a reading's place the local misfit is read by the reading itself:
    // the field shrunk towards it (the best linear predictor of a random
    // effect of variance tau2 seen through a reading of variance s^2).
    let at_reading = |i: usize, (m, var): (Real, Real)| {
        let s2 = samples[i].std * samples[i].std;
        let k = if tau2 > 0.0 { tau2 / (tau2 + s2) } else { 0.0 };
        FieldTerm {
            gap: m + k * (r[i] - m),
            std: ((1.0 - k) * (1.0 - k) * var + k * s2).max(0.0).sqrt(),
            sample: i,
        }
    };
    let mut terms = Vec::with_capacity(n + 1);
    if let Some(c) = field.lowest(&coords) {
        let nearest = (0..n)
            .min_by(|&i, &j| {
                let d = |k: usize| (coords[k][0] - c[0]).hypot(coords[k][1] - c[1]);
                d(i).total_cmp(&d(j))
            })
            .unwrap_or(0);
        terms.push(at(c, nearest));
    }
    let scale = field.best().scale();
    for i in 0..n {
        let here = field.at(coords[i]);
        let below = r[i] - here.0;
        let s = samples[i].std;
        if below / (s * scale.sqrt()) < -BELOW_FIELD_SDS || r[i] < -CROSSED_SDS * s {
            terms.push(FieldTerm {
                gap: r[i],
                std: s,
                sample: i,
            });
        }
        terms.push(at_reading(i, here));
    }
    Some((terms, tau2 > 0.0))
}

/// The readings' places in the contact's two widest directions (about their
/// centroid, in units of the widest spread; zero when they coincide).
fn contact_coordinates(samples: &[GapSample]) -> Vec<[Real; 2]> {
    let n = samples.len() as Real;
    let c = samples
        .iter()
        .fold(Vector3::zeros(), |c, s| c + s.at.coords)
        / n;
    let m = samples.iter().fold(Matrix3::zeros(), |m, s| {
        let d = s.at.coords - c;
        m + d * d.transpose()
    }) / n;
    let eig = SymmetricEigen::new(m);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
    let scale = eig.eigenvalues[order[0]].max(0.0).sqrt();
    let (e1, e2) = (
        eig.eigenvectors.column(order[0]),
        eig.eigenvectors.column(order[1]),
    );
    samples
        .iter()
        .map(|s| {
            if scale > 0.0 {
                let d = s.at.coords - c;
                [d.dot(&e1) / scale, d.dot(&e2) / scale]
            } else {
                [0.0, 0.0]
            }
        })
        .collect()
}

/// The design matrix of the first `k` terms of `(1, u, v, u^2, u v, v^2)`.
fn design(coords: &[[Real; 2]], k: usize) -> DMatrix<Real> {
    DMatrix::from_fn(coords.len(), k, |i, j| {
        let [u, v] = coords[i];
        height_row(u, v)[j]
    })
}

/// The gap fields of every order that could be fitted, averaged with their
/// Akaike weights (`exp(-criterion / 2)`, normalized): the field at a place
/// is the weighted mean of the fits' gaps, and its variance the weighted
/// mean of their variances plus their spread about the mean (the law of
/// total variance), so that which order the readings support is part of the
/// field's uncertainty rather than a choice made and then forgotten (a flat
/// fit of a curved contact that wins the criterion by a little would state
/// its pooled deviation about a gap biased by the curvature it left out).
struct Averaged {
    fits: Vec<Fit>,
    weights: Vec<Real>,
}

impl Averaged {
    /// The average of `fits`; `None` without one.
    fn new(fits: Vec<Fit>) -> Option<Self> {
        let best = fits.iter().map(Fit::criterion).min_by(Real::total_cmp)?;
        let raw: Vec<Real> = fits
            .iter()
            .map(|f| (-0.5 * (f.criterion() - best)).exp())
            .collect();
        let total: Real = raw.iter().sum();
        Some(Self {
            weights: raw.iter().map(|w| w / total).collect(),
            fits,
        })
    }

    /// The averaged field's gap and variance at contact coordinates `u`.
    fn at(&self, u: [Real; 2]) -> (Real, Real) {
        let row = height_row(u[0], u[1]);
        let each: Vec<(Real, Real)> = self.fits.iter().map(|f| f.at(&row)).collect();
        let mean: Real = each
            .iter()
            .zip(&self.weights)
            .map(|((g, _), w)| w * g)
            .sum();
        let var = each
            .iter()
            .zip(&self.weights)
            .map(|((g, v), w)| w * (v + (g - mean) * (g - mean)))
            .sum();
        (mean, var)
    }

    /// The variance of the gap about the smooth field beyond the readings'
    /// own noise (a random effect per place), by the method of moments on
    /// the best fit: `(chi^2 - dof) / sum(w0)` where `chi^2` exceeds its
    /// degrees of freedom by more than [`MISFIT_SDS`] of its standard
    /// deviations (`sqrt(2 dof)`), else 0 (readings that spread as their
    /// stated deviations say: the smooth field describes them).
    fn misfit_variance(&self, w0: &DVector<Real>) -> Real {
        let f = self.best();
        let excess = f.chi2 - f.dof;
        if excess > MISFIT_SDS * (2.0 * f.dof).sqrt() {
            excess / w0.sum()
        } else {
            0.0
        }
    }

    /// The fit of the largest Akaike weight.
    fn best(&self) -> &Fit {
        let best = (0..self.fits.len())
            .max_by(|&i, &j| self.weights[i].total_cmp(&self.weights[j]))
            .unwrap_or(0);
        &self.fits[best]
    }

    /// Where the quadric field is lowest ([`Fit::lowest`]), when one was fitted.
    fn lowest(&self, coords: &[[Real; 2]]) -> Option<[Real; 2]> {
        self.fits.iter().find_map(|f| f.lowest(coords))
    }
}

/// A weighted least-squares fit of the gap field.
struct Fit {
    a: DMatrix<Real>,
    beta: DVector<Real>,
    /// `(A^T W A)^-1` with the readings' own weights.
    inverse: DMatrix<Real>,
    chi2: Real,
    dof: Real,
}

impl Fit {
    /// The fit with Huber weights on top of the readings' own (three
    /// reweightings); `None` when the normal equations are singular.
    fn robust(a: &DMatrix<Real>, r: &DVector<Real>, w0: &DVector<Real>) -> Option<Self> {
        let mut w = w0.clone();
        let mut fit = Self::weighted(a, r, w0, &w)?;
        for _ in 0..3 {
            let scale = (fit.chi2 / fit.dof).max(1.0).sqrt();
            let res = r - &fit.a * &fit.beta;
            for i in 0..r.len() {
                let t = (res[i] * w0[i].sqrt() / scale).abs();
                w[i] = w0[i] * if t > HUBER { HUBER / t } else { 1.0 };
            }
            fit = Self::weighted(a, r, w0, &w)?;
        }
        Some(fit)
    }

    /// The fit with weights `w`; `chi^2` with the readings' own weights `w0`
    /// over the readings Huber's weights keep whole, the rest counted at the
    /// bound (so that the spread is not read from the outliers).
    fn weighted(
        a: &DMatrix<Real>,
        r: &DVector<Real>,
        w0: &DVector<Real>,
        w: &DVector<Real>,
    ) -> Option<Self> {
        let (n, k) = a.shape();
        let aw = DMatrix::from_fn(n, k, |i, j| a[(i, j)] * w[i]);
        let normal = a.transpose() * &aw;
        let chol = normal.cholesky()?;
        let beta = chol.solve(&(aw.transpose() * r));
        let res = r - a * &beta;
        let chi2 = (0..n)
            .map(|i| {
                let t2 = res[i] * res[i] * w0[i];
                if w[i] < w0[i] {
                    // Huber's loss: linear beyond the bound.
                    2.0 * HUBER * t2.sqrt() - HUBER * HUBER
                } else {
                    t2
                }
            })
            .sum();
        // The covariance of a weighted fit with the readings' deviations:
        // (A^T W A)^-1 (A^T W W0^-1 W A) (A^T W A)^-1.
        let inv = chol.inverse();
        let middle = DMatrix::from_fn(k, k, |p, q| {
            (0..n)
                .map(|i| aw[(i, p)] * aw[(i, q)] / w0[i])
                .sum::<Real>()
        });
        Some(Self {
            a: a.clone(),
            beta,
            inverse: &inv * middle * &inv,
            chi2,
            dof: (n - k) as Real,
        })
    }

    /// The variance scale: the reduced `chi^2` where it exceeds 1
    /// (readings spread more than their stated deviations), else 1.
    fn scale(&self) -> Real {
        (self.chi2 / self.dof).max(1.0)
    }

    /// The fitted gap and its variance at the terms `row` of
    /// `(1, u, v, u^2, u v, v^2)` (the fit's first ones).
    fn at(&self, row: &nalgebra::SVector<Real, 6>) -> (Real, Real) {
        let k = self.beta.len();
        let x = row.rows(0, k);
        let gap = x.dot(&self.beta);
        let var = (x.transpose() * &self.inverse * x)[0] * self.scale();
        (gap, var)
    }

    /// The model selection criterion of the fit (Akaike's, `chi^2 + 2k`,
    /// scaled by `CRITERION_PER_TERM`).
    fn criterion(&self) -> Real {
        self.chi2 + CRITERION_PER_TERM * self.a.ncols() as Real
    }

    /// Where a quadric field is lowest, when that lies no farther from the
    /// readings' centroid than they do (a curved contact's closest place
    /// between its readings).
    fn lowest(&self, coords: &[[Real; 2]]) -> Option<[Real; 2]> {
        if self.beta.len() != 6 {
            return None;
        }
        let b = &self.beta;
        let h = nalgebra::Matrix2::new(2.0 * b[3], b[4], b[4], 2.0 * b[5]);
        let c = h.cholesky()?.solve(&nalgebra::Vector2::new(-b[1], -b[2]));
        // Within the readings' reach from their centroid (a test that does
        // not turn with the axes, which are arbitrary on a round contact).
        let reach = coords
            .iter()
            .fold(0.0, |r: Real, x| r.max(x[0].hypot(x[1])));
        (c[0].hypot(c[1]) <= reach).then_some([c[0], c[1]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, gap: impl Fn(Real, Real) -> Real, s: Real) -> Vec<GapSample> {
        (0..n * n)
            .map(|k| {
                let (x, y) = ((k % n) as Real * 0.01, (k / n) as Real * 0.01);
                GapSample {
                    at: Point3::new(x, y, 0.0),
                    gap: gap(x, y),
                    std: s,
                }
            })
            .collect()
    }

    #[test]
    fn a_flat_contact_reads_its_pooled_gap() {
        // 25 readings of one gap: a constant field's pooled deviation is
        // s / 5, where one reading's is s; the plane and quadric fits, which
        // the criterion weighs less, widen it away from the readings' centre.
        let s = 1e-3;
        let terms = field_terms(&grid(5, |_, _| 1e-3, s)).unwrap();
        let centre = terms.iter().find(|t| t.sample == 12).unwrap();
        assert!((centre.gap - 1e-3).abs() < 1e-12, "{centre:?}");
        assert!(
            centre.std > s / 5.0 && centre.std < 1.2 * s / 5.0,
            "{centre:?}"
        );
        let p = field_probability(&grid(5, |_, _| 1e-3, s)).unwrap();
        let pooled = crate::probability::normal_cdf(-1e-3 / (s / 5.0));
        let one = crate::probability::normal_cdf(-1e-3 / s);
        assert!(
            p > pooled && p < 1e-3 * one,
            "P {p}: pooled {pooled}, one reading {one}"
        );
    }

    #[test]
    fn a_cone_shaped_contact_is_read_at_its_apex_reading() {
        // A corner pressed towards a face: the gap rises as a cone from the
        // grid's centre (1 mm), which no constant, plane or quadric follows;
        // the readings' excess spread is the gap's own variation about the
        // field, so the apex is read from its own reading (within a few of
        // its standard deviations), not from the smooth field above it.
        let s = 1e-4;
        let cone = |x: Real, y: Real| 1e-3 + 0.2 * (x - 0.03).hypot(y - 0.03);
        let r = grid(7, cone, s);
        let min = field_minimum(&r).unwrap();
        assert!((min.gap - 1e-3).abs() < 3.0 * s, "{min:?}");
        assert!(min.std >= 0.9 * s && min.std < 3.0 * s, "{min:?}");
        // The smooth field alone reads the apex more than 1 mm too far.
        let coords = contact_coordinates(&r);
        let g = DVector::from_iterator(r.len(), r.iter().map(|x| x.gap));
        let w0 = DVector::from_element(r.len(), 1.0 / (s * s));
        let fits = [1usize, 3, 6]
            .into_iter()
            .filter_map(|k| Fit::robust(&design(&coords, k), &g, &w0))
            .collect();
        let field = Averaged::new(fits).unwrap();
        let above = field.at(coords[24]).0 - 1e-3;
        assert!(above > 10.0 * s, "{above}");
        let tau2 = field.misfit_variance(&w0);
        assert!(tau2 > 4.0 * s * s, "{tau2}");
    }

    #[test]
    fn a_reading_far_below_the_field_reads_the_contact() {
        let s = 1e-3;
        let mut r = grid(5, |_, _| 5e-3, s);
        r[12].gap = -2e-3;
        let p = field_probability(&r).unwrap();
        assert!(
            (p - crate::probability::normal_cdf(2.0)).abs() < 1e-9,
            "P {p}"
        );
    }

    /// The mean `P` over 200 noise draws (deviation 1 mm) of the readings
    /// of a 9 x 9 grid at gap `offset` over its inner 5 x 5 and `offset +
    /// jump` beyond (the whole grid, or with `inner_only` the inner part
    /// alone).
    fn mean_over_draws(offset: Real, jump: Real, inner_only: bool) -> Real {
        let s = 1e-3;
        let mut rng = crate::sample::NormalRng::new(7);
        let total: Real = (0..200)
            .map(|_| {
                let r: Vec<GapSample> = grid(9, |_, _| offset, s)
                    .into_iter()
                    .map(|g| {
                        let edge = (g.at.x - 0.04).abs().max((g.at.y - 0.04).abs());
                        let beyond = if edge > 0.025 { jump } else { 0.0 };
                        (
                            edge,
                            GapSample {
                                gap: g.gap + beyond + s * rng.normal(),
                                ..g
                            },
                        )
                    })
                    .filter(|(edge, _)| !inner_only || *edge < 0.025)
                    .map(|(_, g)| g)
                    .collect();
                field_probability(&r).unwrap()
            })
            .sum();
        total / 200.0
    }

    #[test]
    fn a_flat_contact_beside_a_jump_reads_as_its_flat_part() {
        // A piano's underside resting on a table (gap 0 over the inner 5 x 5
        // of a 9 x 9 grid), read beyond the table's edge against its side
        // faces, 10 deviations lower: no smooth field follows the jump, and
        // the readings far above the contact say nothing of whether it
        // crosses. Over noise draws, the contact reads as its flat part
        // alone does, at touching and 1 deviation clear.
        let s = 1e-3;
        for offset in [0.0, s] {
            let with_jump = mean_over_draws(offset, 10.0 * s, false);
            let flat = mean_over_draws(offset, 0.0, true);
            assert!(
                (with_jump - flat).abs() < 0.05,
                "gap {offset}: mean P {with_jump} beside the jump, {flat} without it"
            );
        }
        assert!(mean_over_draws(s, 10.0 * s, false) < 0.25);
    }

    #[test]
    fn a_curved_contact_is_read_at_its_closest_place() {
        // A bowl: the gap is smallest at the grid's centre (1 mm).
        let s = 1e-4;
        let r = grid(
            7,
            |x, y| 1e-3 + 2.0 * ((x - 0.03).powi(2) + (y - 0.03).powi(2)),
            s,
        );
        let p = field_probability(&r).unwrap();
        assert!(p < 1e-12, "P {p}");
        // Moved down by 1 mm, the centre touches: P near 1/2.
        let r: Vec<GapSample> = r
            .iter()
            .map(|g| GapSample {
                gap: g.gap - 1e-3,
                ..*g
            })
            .collect();
        let p = field_probability(&r).unwrap();
        assert!((p - 0.5).abs() < 0.05, "P {p}");
    }

    #[test]
    fn too_few_or_exact_readings_are_not_fitted() {
        let r = grid(1, |_, _| 1e-3, 1e-3);
        assert!(field_probability(&r).is_none());
        let mut r = grid(3, |_, _| 1e-3, 1e-3);
        r[0].std = 0.0;
        assert!(field_probability(&r).is_none());
    }
}

#[cfg(test)]
mod invariance {
    use super::*;

    #[test]
    fn a_rigid_motion_and_another_order_read_the_same() {
        let mut state = 7u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as Real / (1u64 << 53) as Real - 0.5
        };
        let r: Vec<GapSample> = (0..40)
            .map(|_| {
                let (x, y) = (0.1 * rnd(), 0.1 * rnd());
                GapSample {
                    at: Point3::new(x, y, 0.002 * rnd()),
                    gap: 0.5 * (x * x + y * y) + 1e-3 * rnd(),
                    std: 1e-3 * (1.0 + rnd()),
                }
            })
            .collect();
        let p = field_probability(&r).unwrap();
        let t = crate::math::Pose::new(Vector3::new(0.3, -1.0, 2.0), Vector3::new(0.4, 1.1, -0.7));
        let mut moved: Vec<GapSample> =
            r.iter().map(|s| GapSample { at: t * s.at, ..*s }).collect();
        moved.reverse();
        let q = field_probability(&moved).unwrap();
        assert!((p - q).abs() < 1e-9, "{p} vs {q}");
    }
}
