//! The probability that two sampled surfaces cross at a contact, from the
//! gaps that their facing surface elements read there.

use crate::probability::gaussian::wrong_side;
use crate::Real;

/// What one facing pair within reach reads: the two elements, the gap and its
/// standard deviation, and at which contact
/// ([`contact_probability`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementReading {
    /// The element of one side (the probe's, as a patch reads it; A's, once
    /// a query pools both sides' readings): [`contact_probability`] takes the
    /// readings of one pair of elements, from either side, by `(own, other)`,
    /// so pooled readings must name the two sides in one order.
    pub own: u32,
    /// The element of the other side.
    pub other: u32,
    /// The gap between the two fitted surfaces there.
    pub gap: Real,
    /// Its standard deviation.
    pub std: Real,
    /// Whether the probe lies beside the facing element (the gap read between
    /// two surfaces' ends) rather than over it.
    pub beside: bool,
    /// The contact the reading belongs to (a query's connected near region):
    /// readings of different contacts are never pooled.
    pub contact: u32,
}

/// How far apart, in the standard deviations of their difference, two
/// element pairs' gaps may read and still be taken for readings of one
/// contact ([`contact_probability`]).
const CONTACT_WINDOW: Real = 2.0;

/// The probability that the two sampled surfaces cross, from the facing
/// pairs' readings ([`ElementReading`]): the largest over the contacts
/// (`contact`) of each contact's crossing probability.
///
/// At one contact each element pair is read once, by its most critical
/// reading (the smallest `gap / std`) among those read over the facing
/// element, or among its readings beside it where it has none over it (two
/// surfaces' ends say less of a crossing than one surface over the other).
/// The most critical of these read over a surface places the contact (one
/// beside only where none is over). Readings are then taken once per element
/// (an element's surface error is one random field: two readings sharing an
/// element are not independent): the contact's own reading first, then the
/// most precise.
///
/// The readings whose gaps agree with the contact's within `CONTACT_WINDOW`
/// (2) standard deviations of their difference read the same contact: they
/// are independent estimates of the gap there, and their inverse-variance
/// mean `g` with standard deviation `s = (sum 1/s_k^2)^(-1/2)` gives
/// `P = Phi(-g / s)`. (A small element's imprecise reading at the contact
/// keeps its elements' other readings out: its surface is read as its own, so
/// a face split into a large and a small element is as uncertain as the
/// small one where it meets the other surface.)
///
/// The largest single tail `max_k Phi(-g_k / s_k)` reads the minimum of many
/// noisy readings, which is biased towards a crossing wherever several
/// elements face each other; the standardized residuals of the single
/// readings against exact geometry are standard normal, so the readings
/// themselves are honest and the aggregation is what must not overstate.
/// 0 without readings.
pub fn contact_probability(readings: &[ElementReading]) -> Real {
    let mut contacts: Vec<u32> = readings.iter().map(|r| r.contact).collect();
    contacts.sort_unstable();
    contacts.dedup();
    contacts
        .into_iter()
        .map(|c| one_contact(readings.iter().filter(|r| r.contact == c).collect()))
        .fold(0.0, Real::max)
}

/// A key of a reading's element pair that does not change when the two
/// sides are swapped (ties are broken by it, so that swapping A and B reads
/// the same readings).
fn pair_key(r: &ElementReading) -> (u32, u32) {
    (r.own.min(r.other), r.own.max(r.other))
}

/// A reading's standardized gap (infinite for an exact one).
fn z(r: &ElementReading) -> Real {
    if r.std > 0.0 {
        r.gap / r.std
    } else if r.gap > 0.0 {
        Real::INFINITY
    } else {
        Real::NEG_INFINITY
    }
}

/// The crossing probability of one contact's readings
/// ([`contact_probability`]).
fn one_contact(mut order: Vec<&ElementReading>) -> Real {
    // One reading per element pair: over before beside, then most critical.
    order.sort_by(|x, y| {
        (x.own, x.other, x.beside)
            .cmp(&(y.own, y.other, y.beside))
            .then(z(x).total_cmp(&z(y)))
    });
    order.dedup_by(|x, y| (x.own, x.other) == (y.own, y.other));
    // The contact is placed by the most critical reading over a surface, by
    // one beside only where there is none over.
    order.sort_by(|x, y| x.beside.cmp(&y.beside).then(z(x).total_cmp(&z(y))));
    let Some(first) = order.first() else {
        return 0.0;
    };
    if first.std.is_nan() || first.std <= 0.0 {
        return wrong_side(first.gap, first.std);
    }
    // The contact's own reading first, then the most precise: readings far
    // from the contact agree with it only loosely, and must not keep out a
    // more precise reading of the same elements nearer to it.
    // (Ties by the element pair, named alike from either side: swapping A
    // and B reads the same readings.)
    order[1..].sort_by(|x, y| x.std.total_cmp(&y.std).then(pair_key(x).cmp(&pair_key(y))));
    inverse_variance_mean(&disjoint_within(&order))
}

/// The readings of `order` (the contact's own first) that agree with the
/// first within `CONTACT_WINDOW` standard deviations of their difference, each
/// element taken once, in `order`'s order.
fn disjoint_within<'a>(order: &[&'a ElementReading]) -> Vec<&'a ElementReading> {
    let (g0, s0) = (order[0].gap, order[0].std);
    let (mut used_own, mut used_other): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
    let mut out = Vec::new();
    for &r in order {
        let (g, s) = (r.gap, r.std);
        if s.is_nan() || s <= 0.0 || used_own.contains(&r.own) || used_other.contains(&r.other) {
            continue;
        }
        if (g - g0).abs() > CONTACT_WINDOW * (s * s + s0 * s0).sqrt() {
            continue;
        }
        used_own.push(r.own);
        used_other.push(r.other);
        out.push(r);
    }
    out
}

/// `Phi(-g / s)` of the readings' inverse-variance mean `g` and its standard
/// deviation `s` (at least one reading).
fn inverse_variance_mean(readings: &[&ElementReading]) -> Real {
    let (mut weights, mut weighted) = (0.0, 0.0);
    for r in readings {
        let w = 1.0 / (r.std * r.std);
        weights += w;
        weighted += w * r.gap;
    }
    wrong_side(weighted / weights, weights.recip().sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::probability::normal_cdf;

    /// Readings of a flat contact at true gap `gap`: one element pair per
    /// place of a `n x n` grid, each read with standard deviation `s`.
    fn flat(n: u32, gap: Real, s: Real) -> Vec<ElementReading> {
        (0..n * n)
            .map(|k| ElementReading {
                own: k,
                other: k,
                gap,
                std: s,
                beside: false,
                contact: 0,
            })
            .collect()
    }

    #[test]
    fn agreeing_independent_readings_are_pooled_by_inverse_variance() {
        // Nine readings of one gap, 1 mm each: the mean of nine has a third
        // of the deviation.
        let p = contact_probability(&flat(3, 1e-3, 1e-3));
        assert!((p - normal_cdf(-3.0)).abs() < 1e-12, "P {p}");
        // A reading beyond the window (5 sd of the difference) is another
        // place of the contact, not read with it.
        let mut r = flat(1, 1e-3, 1e-3);
        r.push(ElementReading {
            own: 7,
            other: 7,
            gap: 1e-3 + 5.0 * 2f64.sqrt() * 1e-3,
            ..r[0]
        });
        assert!((contact_probability(&r) - normal_cdf(-1.0)).abs() < 1e-12);
    }

    #[test]
    fn contacts_are_read_apart_and_the_most_probable_one_is_p() {
        let mut a = flat(4, 5e-3, 1e-3);
        let mut b = flat(1, -2e-3, 1e-3);
        for r in &mut b {
            r.contact = 1;
            r.own += 100;
            r.other += 100;
        }
        let pa = contact_probability(&a);
        a.append(&mut b);
        let p = contact_probability(&a);
        assert!(pa < 1e-6);
        assert!((p - normal_cdf(2.0)).abs() < 1e-12, "P {p}");
        assert_eq!(contact_probability(&[]), 0.0);
    }

    #[test]
    fn readings_sharing_an_element_count_once() {
        // Ten readings of one element of A against ten of B: one element's
        // error, so the pooled deviation is not shrunk by ten.
        let readings: Vec<ElementReading> = (0..10u32)
            .map(|k| ElementReading {
                own: 0,
                other: k,
                gap: 1e-3,
                std: 1e-3,
                beside: false,
                contact: 0,
            })
            .collect();
        let p = contact_probability(&readings);
        assert!((p - normal_cdf(-1.0)).abs() < 1e-12, "P {p}");
        // Swapping the sides' names reads the same.
        let swapped: Vec<ElementReading> = readings
            .iter()
            .map(|r| ElementReading {
                own: r.other,
                other: r.own,
                ..*r
            })
            .collect();
        assert_eq!(contact_probability(&swapped), p);
    }
}
