//! Thresholds and the reported collision state.

use crate::error::{Error, Result};
use crate::Real;

/// The decided state of a pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CollisionState {
    /// `P <= threshold_free`: collision-free.
    Free,
    /// `threshold_free < P < threshold_collision`: not enough information to decide.
    Contact,
    /// `P >= threshold_collision`: in collision.
    Collision,
}

impl CollisionState {
    /// `"free"`, `"contact"` or `"collision"`.
    pub fn name(self) -> &'static str {
        match self {
            CollisionState::Free => "free",
            CollisionState::Contact => "contact",
            CollisionState::Collision => "collision",
        }
    }
}

/// The two thresholds `A >= 0.5 >= B` of the paper on the collision probability.
///
/// (The paper's text states the comparisons the other way round; that is a typo.)
/// Conservative users raise `collision` and lower `free`, widening the undecided band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thresholds {
    /// `A`: `P >= A` is in-collision (default 0.9).
    pub collision: Real,
    /// `B`: `P <= B` is collision-free (default 0.1).
    pub free: Real,
}

impl Default for Thresholds {
    fn default() -> Self {
        Self {
            collision: 0.9,
            free: 0.1,
        }
    }
}

impl Thresholds {
    /// Validated thresholds: `0 <= free <= 0.5 <= collision <= 1`.
    pub fn new(collision: Real, free: Real) -> Result<Self> {
        let t = Self { collision, free };
        t.validate()?;
        Ok(t)
    }

    /// Checks `0 <= free <= 0.5 <= collision <= 1` (all finite).
    pub fn validate(&self) -> Result<()> {
        let ok = self.free.is_finite()
            && self.collision.is_finite()
            && (0.0..=0.5).contains(&self.free)
            && (0.5..=1.0).contains(&self.collision);
        if ok {
            Ok(())
        } else {
            Err(Error::invalid(format!(
                "thresholds must satisfy 0 <= threshold_free <= 0.5 <= threshold_collision <= 1, \
                 got threshold_free = {}, threshold_collision = {}",
                self.free, self.collision
            )))
        }
    }

    /// The state for collision probability `p`.
    pub fn state(&self, p: Real) -> CollisionState {
        if p >= self.collision {
            CollisionState::Collision
        } else if p <= self.free {
            CollisionState::Free
        } else {
            CollisionState::Contact
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn states_and_validation() {
        let t = Thresholds::new(0.8, 0.2).unwrap();
        assert_eq!(t.state(0.85), CollisionState::Collision);
        assert_eq!(t.state(0.8), CollisionState::Collision);
        assert_eq!(t.state(0.5), CollisionState::Contact);
        assert_eq!(t.state(0.2), CollisionState::Free);
        assert!(Thresholds::new(0.2, 0.8).is_err());
        assert!(Thresholds::new(0.4, 0.1).is_err());
        assert!(Thresholds::new(0.9, -0.1).is_err());
        assert!(Thresholds::new(f64::NAN, 0.1).is_err());
        let e = Thresholds::new(0.3, 0.6).unwrap_err().to_string();
        assert!(e.contains("threshold_free"), "{e}");
    }
}
