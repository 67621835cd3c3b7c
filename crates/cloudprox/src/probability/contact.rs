//! The probability that two sampled surfaces cross at a contact, from the
//! gaps that their facing surface elements read there.

use crate::math::{Point3, Vector3};
use crate::probability::gap_field::{field_minimum, field_probability, GapSample};
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
    /// The part of `std` from the two fitted surfaces alone, without where
    /// their sampled edges are: what differs by noise between readings of one
    /// pair of elements ([`contact_probability`]).
    pub fit_std: Real,
    /// Whether the probe lies beside the facing element (the gap read between
    /// two surfaces' ends), or the reading is a clearance measured across the
    /// probe's own end (closer to its element's tangent plane than to its
    /// normal), rather than one surface over the other.
    pub beside: bool,
    /// The contact the reading belongs to (a query's connected near region):
    /// readings of different contacts are read apart.
    pub contact: u32,
    /// Where the pair lies, in a frame shared by the query's readings; `None`
    /// where it is not known (the contact is then read at its most critical
    /// pair, see [`contact_probability`]).
    pub at: Option<Point3>,
    /// The unit direction the gap was measured along, from A towards B
    /// (zero where the reading has none to compare: an exact side's signed
    /// distance).
    pub direction: Vector3,
}

/// The probability that the two sampled surfaces cross, from the facing
/// pairs' readings ([`ElementReading`]): the largest over the contacts
/// (`contact`) of each contact's crossing probability.
///
/// At one contact each element pair is read once (see below), among
/// its readings over the facing element, or among those beside it (or
/// reading a clearance across the probe's own end, see
/// [`ElementReading::beside`]) where it has none over it: two surfaces' ends
/// say less of a crossing than one surface over the other. The contact's `P` is
/// `Phi(-g / s)` of its most critical pair (the smallest `g / s`), a pair
/// read over a surface before one read beside.
///
/// The readings of one pair share the two fitted surfaces, so the most
/// critical of them reads the minimum of one correlated noisy field, which
/// is biased towards a crossing (on parallel plates by 1.25 standard
/// deviations at the contact); the pair's most precise reading is not. So a
/// pair is read at its most precise reading, unless its most critical lies
/// more than 3 standard deviations of the two fits (`fit_std`) below it: the
/// gap then truly varies across the pair, and the most critical reading is
/// where the surfaces come closest. The
/// pairs of a contact read different places of it: the most critical pair is
/// where the surfaces come closest (on two spheres the pairs' gaps rise away
/// from the closest approach faster than the noise), and pooling it with the
/// others reads a gap that is too large.
///
/// The rule takes two facing surfaces whose fits agree with being parallel
/// within their noise for parallel: a relative tilt smaller than a few times
/// the fits' slope error is not resolved, and a corner that it alone brings
/// through the other surface is read at the gap where the fits are best.
/// 0 without readings.
pub fn contact_probability(readings: &[ElementReading]) -> Real {
    let mut contacts: Vec<u32> = readings.iter().map(|r| r.contact).collect();
    contacts.sort_unstable();
    contacts.dedup();
    contacts
        .into_iter()
        .map(|c| {
            one_contact(
                &readings
                    .iter()
                    .filter(|r| r.contact == c)
                    .collect::<Vec<_>>(),
            )
        })
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

/// How many standard deviations of their two readings an element pair's most
/// critical reading must lie below its most precise one to be read instead
/// ([`pair_reading`]).
const VARIATION_SDS: Real = 3.0;

/// The crossing probability of one contact's readings
/// ([`contact_probability`]): the readings turned to one orientation
/// ([`oriented`]), one per element pair ([`pairs`]), those over a surface
/// pooled into a gap field where their places are known
/// ([`field_probability`]); else the most critical pair's.
fn one_contact(readings: &[&ElementReading]) -> Real {
    let oriented = oriented(readings);
    let chosen = pairs(oriented.iter().collect());
    if let Some(p) = pooled(&chosen) {
        return p;
    }
    first_by(chosen, z).map_or(0.0, |r| wrong_side(r.gap, r.std))
}

/// The first of `chosen` (one reading per element pair) by `key`, those over
/// a surface before those beside it, ties broken by the element pair.
fn first_by(
    chosen: Vec<&ElementReading>,
    key: fn(&ElementReading) -> Real,
) -> Option<&ElementReading> {
    chosen.into_iter().min_by(|x, y| {
        x.beside
            .cmp(&y.beside)
            .then(key(x).total_cmp(&key(y)))
            .then(pair_key(x).cmp(&pair_key(y)))
    })
}

/// Where the surfaces come closest, as [`contact_probability`] reads them:
/// per contact (turned to its one orientation, one reading per element
/// pair), the smallest term of its pooled gap field where it pools them (and
/// `pool` asks for it), else its nearest reading ([`nearest_of`]); over the contacts, the smallest gap,
/// those over a surface before those beside it. `None` without readings.
///
/// The gap and standard deviation are one of the terms whose largest
/// `Phi(-gap / std)` [`contact_probability`] is, so that is at least
/// `Phi(-gap / std)` of this reading; where a contact's readings are one
/// element pair, the two are equal.
pub(crate) fn nearest_reading(readings: &[ElementReading], pool: bool) -> Option<ElementReading> {
    let mut contacts: Vec<u32> = readings.iter().map(|r| r.contact).collect();
    contacts.sort_unstable();
    contacts.dedup();
    contacts
        .into_iter()
        .filter_map(|c| {
            let of: Vec<&ElementReading> = readings.iter().filter(|r| r.contact == c).collect();
            contact_nearest(&of, pool)
        })
        .min_by(|x, y| {
            x.beside
                .cmp(&y.beside)
                .then(x.gap.total_cmp(&y.gap))
                .then(pair_key(x).cmp(&pair_key(y)))
        })
}

/// The readings over a surface among `chosen` (one per element pair) pooled
/// into the contact's gap field ([`field_probability`]), in an order that
/// does not depend on which side is A; `None` without three of them or
/// where one's place is unknown.
fn pooled(chosen: &[&ElementReading]) -> Option<Real> {
    field_probability(&pooled_samples(chosen)?.1)
}

/// The readings over a surface among `chosen`, in an order that does not
/// depend on which side is A, and their places and gaps as the gap field
/// reads them; `None` where one's place is unknown.
fn pooled_samples<'a>(
    chosen: &[&'a ElementReading],
) -> Option<(Vec<&'a ElementReading>, Vec<GapSample>)> {
    let mut over: Vec<&ElementReading> = chosen.iter().copied().filter(|r| !r.beside).collect();
    over.sort_by(|x, y| {
        pair_key(x)
            .cmp(&pair_key(y))
            .then(x.gap.total_cmp(&y.gap))
            .then(x.std.total_cmp(&y.std))
    });
    let samples = over
        .iter()
        .map(|r| {
            r.at.map(|at| GapSample {
                at,
                gap: r.gap,
                std: r.std,
            })
        })
        .collect::<Option<Vec<_>>>()?;
    Some((over, samples))
}

/// The nearest place of one contact's readings: the pooled gap field's
/// smallest term ([`field_minimum`]) where the readings are pooled (the
/// reading nearest it, with the field's gap and standard deviation), else
/// (or without `pool`) its nearest reading ([`nearest_of`]).
fn contact_nearest(readings: &[&ElementReading], pool: bool) -> Option<ElementReading> {
    let oriented = oriented(readings);
    let chosen = pairs(oriented.iter().collect());
    let pooled = pool.then(|| pooled_samples(&chosen)).flatten();
    let field = pooled.and_then(|(over, samples)| {
        let t = field_minimum(&samples)?;
        Some(ElementReading {
            gap: t.gap,
            std: t.std,
            ..*over[t.sample]
        })
    });
    field.or_else(|| nearest_of(&chosen).copied())
}

/// The nearest of `chosen` (one reading per element pair): among those over
/// a surface (beside, where none is), the most precise of the readings whose
/// gap lies within `VARIATION_SDS` standard deviations of the two fits of
/// the smallest gap, as [`pair_reading`] reads one pair's readings: the
/// smallest of many noisy gaps is biased towards the surfaces (a small,
/// noisy element's reading most of all), and a reading as near within the
/// noise reads the gap where the fits are best.
fn nearest_of<'a>(chosen: &[&'a ElementReading]) -> Option<&'a ElementReading> {
    let over = chosen.iter().any(|r| !r.beside);
    let kept: Vec<&ElementReading> = chosen
        .iter()
        .copied()
        .filter(|r| !over || !r.beside)
        .collect();
    let nearest = first_by(kept.clone(), |r| r.gap)?;
    kept.into_iter()
        .filter(|r| r.gap - nearest.gap <= VARIATION_SDS * r.fit_std.hypot(nearest.fit_std))
        .min_by(|x, y| x.std.total_cmp(&y.std).then(pair_key(x).cmp(&pair_key(y))))
}

/// The readings with the contact's one orientation: a reading over a surface
/// measured against the direction its contact's readings over surfaces share
/// (their directions' sum, each weighted by its precision) is read along the
/// other way (its gap negated).
///
/// A facing pair's direction is its facing element's normal, turned from A
/// towards B by the patch's separating surface at the pair. Where that
/// surface is curved at touching (it passes through the noise of both
/// clouds), a few pairs of one flat contact are turned the other way and
/// read the two surfaces in the wrong order: a clearance of 6 mm as a
/// crossing of 6 mm. Readings without a direction (an exact side's) are kept.
fn oriented(readings: &[&ElementReading]) -> Vec<ElementReading> {
    let shared = readings
        .iter()
        .filter(|r| !r.beside && r.std > 0.0)
        .fold(Vector3::zeros(), |d, r| d + r.direction / (r.std * r.std));
    let shared = shared.try_normalize(0.0).unwrap_or_else(Vector3::zeros);
    readings
        .iter()
        .map(|&&r| {
            if !r.beside && r.direction.dot(&shared) < -ORIENTATION_COS {
                ElementReading {
                    gap: -r.gap,
                    direction: -r.direction,
                    ..r
                }
            } else {
                r
            }
        })
        .collect()
}

/// How far (as the cosine of the angle to the contact's shared direction) a
/// reading's direction must point the other way to be turned ([`oriented`]).
const ORIENTATION_COS: Real = 0.5;

/// Each element pair's reading ([`pair_reading`]): over the facing element
/// where the pair has such readings, beside it where it has none.
fn pairs(mut order: Vec<&ElementReading>) -> Vec<&ElementReading> {
    order.sort_by_key(|r| (r.own, r.other, r.beside));
    order
        .chunk_by(|x, y| (x.own, x.other) == (y.own, y.other))
        .filter_map(|pair| {
            let over = pair.partition_point(|r| !r.beside);
            pair_reading(if over > 0 { &pair[..over] } else { pair })
        })
        .collect()
}

/// The reading of one element pair from its readings at different probes
/// (`None` without any): the most precise, unless the most critical lies more
/// than `VARIATION_SDS` standard deviations of the two fits below it.
///
/// The readings of one pair share the two fitted surfaces: they differ by the
/// fits' slope and curvature errors, which grow towards the elements' edges,
/// and by how the true gap varies over the pair. The most critical of many
/// such readings is biased towards a crossing (on two parallel plates, by 1.25
/// standard deviations at the contact); the most precise reads the gap where
/// the fits are best. Where the gap truly varies across the pair by more than
/// the fits' noise (a pair straddling a crossing, a tilted or curved contact,
/// a face ending at an angle over another), the most critical reading is
/// where the surfaces come closest. (Where a sampled surface ends is uncertain
/// by more than its fit, but alike for the readings near that end: it does
/// not make one of them look closer than another by chance.)
fn pair_reading<'a>(readings: &[&'a ElementReading]) -> Option<&'a ElementReading> {
    let by = |key: fn(&ElementReading) -> Real| {
        readings
            .iter()
            .copied()
            .min_by(|x, y| key(x).total_cmp(&key(y)))
    };
    let (precise, critical) = (by(|r| r.std)?, by(z)?);
    let spread = precise.fit_std.hypot(critical.fit_std);
    let varies = precise.gap - critical.gap > VARIATION_SDS * spread || !spread.is_finite();
    Some(if varies { critical } else { precise })
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
                fit_std: s,
                beside: false,
                contact: 0,
                at: None,
                direction: Vector3::zeros(),
            })
            .collect()
    }

    /// One reading of the pair `(own, other)`.
    fn reading(own: u32, other: u32, gap: Real, std: Real) -> ElementReading {
        ElementReading {
            own,
            other,
            gap,
            std,
            fit_std: std,
            beside: false,
            contact: 0,
            at: None,
            direction: Vector3::zeros(),
        }
    }

    #[test]
    fn the_most_critical_pair_places_the_contact() {
        // Nine pairs of a contact: the closest (gap 1 mm, 1 mm) is P, the
        // others read farther places of it.
        let mut r = flat(3, 4e-3, 1e-3);
        r[4].gap = 1e-3;
        let p = contact_probability(&r);
        assert!((p - normal_cdf(-1.0)).abs() < 1e-12, "P {p}");
    }

    #[test]
    fn a_pair_is_read_where_its_fits_are_most_precise() {
        // One pair at four probes: the most critical (gap 0.5 mm, 1 mm)
        // lies within the noise of the most precise (1 mm, 0.5 mm), which
        // reads the pair.
        let r = [
            reading(0, 0, 1e-3, 0.5e-3),
            reading(0, 0, 0.5e-3, 1e-3),
            reading(0, 0, 2e-3, 1e-3),
            reading(0, 0, 1.5e-3, 0.8e-3),
        ];
        let p = contact_probability(&r);
        assert!((p - normal_cdf(-2.0)).abs() < 1e-12, "P {p}");
        // A critical reading more than 3 sd of the two below the precise one
        // is a place where the surfaces truly come closer: it reads the pair.
        let deep = -3.5e-3;
        let r = [reading(0, 0, 1e-3, 0.5e-3), reading(0, 0, deep, 1e-3)];
        let p = contact_probability(&r);
        assert!((p - normal_cdf(3.5)).abs() < 1e-12, "P {p}");
        assert!(1e-3 - deep > VARIATION_SDS * (0.5e-3f64).hypot(1e-3));
    }

    #[test]
    fn readings_over_a_surface_come_before_those_beside_it() {
        // A pair read beside (an end, 0.1 mm, 1 mm) and another over a
        // surface (3 mm, 1 mm): the one over reads the contact.
        let mut r = vec![reading(0, 0, 1e-4, 1e-3), reading(1, 1, 3e-3, 1e-3)];
        r[0].beside = true;
        let p = contact_probability(&r);
        assert!((p - normal_cdf(-3.0)).abs() < 1e-12, "P {p}");
        // Within one pair too: its readings over the facing element count.
        r[1] = reading(0, 0, 3e-3, 1e-3);
        assert_eq!(contact_probability(&r), p);
        // Only beside: they read it.
        r.truncate(1);
        let p = contact_probability(&r);
        assert!((p - normal_cdf(-0.1)).abs() < 1e-12, "P {p}");
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
    fn swapping_the_sides_names_reads_the_same() {
        let readings: Vec<ElementReading> = (0..10u32)
            .map(|k| reading(k % 3, k, 1e-3 + 1e-4 * Real::from(k), 1e-3))
            .collect();
        let p = contact_probability(&readings);
        let swapped: Vec<ElementReading> = readings
            .iter()
            .map(|r| ElementReading {
                own: r.other,
                other: r.own,
                ..*r
            })
            .collect();
        assert_eq!(contact_probability(&swapped), p);
        assert!((p - normal_cdf(-1.0)).abs() < 1e-12, "P {p}");
    }
}
