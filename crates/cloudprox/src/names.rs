//! Lowercase names of the option enums ([`crate::classify::Surface`],
//! [`crate::classify::SocpSolver`], [`crate::probability::Aggregation`],
//! [`crate::query::QueryModel`], [`crate::uncertainty::RobustModel`]), as the
//! Python package, the command line and error messages spell them.
//!
//! Each enum lists its names once, beside its definition, with
//! [`named_options!`]: that gives it `ALL` (every value, in declaration
//! order), `OPTION` (what the option is called), `name()`, `from_name()`,
//! [`std::fmt::Display`] (the name) and [`std::str::FromStr`] (an unknown name
//! is [`crate::Error::InvalidInput`] naming the option and the valid names).

use crate::error::Error;

/// The error of an unknown name: `unknown <option> '<given>'; valid names:
/// 'a', 'b'`.
pub fn unknown_name<'a>(
    option: &str,
    given: &str,
    valid: impl IntoIterator<Item = &'a str>,
) -> Error {
    let valid: Vec<String> = valid.into_iter().map(|n| format!("'{n}'")).collect();
    Error::invalid(format!(
        "unknown {option} '{given}'; valid names: {}",
        valid.join(", ")
    ))
}

/// Gives an option enum its names: `ALL`, `OPTION`, `name()`, `from_name()`,
/// `Display` and `FromStr` (see the [module documentation](self)).
///
/// ```ignore
/// named_options!(Surface, "surface", { Linear => "linear", Quadric => "quadric" });
/// ```
///
/// (The inner form `named_options!(@names Ty, "option", [A, B])` adds what
/// needs only `name()` and `from_name()`.)
macro_rules! named_options {
    (@names $ty:ident, $option:literal, [$($variant:ident),+ $(,)?]) => {
        impl $ty {
            /// Every value, in declaration order.
            pub const ALL: &'static [$ty] = &[$($ty::$variant),+];

            /// What the option is called (in requests, on the command line and
            /// in error messages).
            pub const OPTION: &'static str = $option;
        }

        impl ::std::fmt::Display for $ty {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl ::std::str::FromStr for $ty {
            type Err = $crate::error::Error;

            fn from_str(s: &str) -> ::std::result::Result<Self, Self::Err> {
                Self::from_name(s).ok_or_else(|| {
                    $crate::names::unknown_name(
                        $option,
                        s,
                        Self::ALL.iter().map(|v| v.name()),
                    )
                })
            }
        }

        // Every variant is in `ALL`: this match fails to compile otherwise.
        const _: fn($ty) = |v| match v {
            $($ty::$variant => {})+
        };
    };
    ($ty:ident, $option:literal, { $($variant:ident => $name:literal),+ $(,)? }) => {
        $crate::names::named_options!(@names $ty, $option, [$($variant),+]);

        impl $ty {
            /// Parses a lowercase name (see [`Self::ALL`]); `None` if unknown.
            /// [`str::parse`] gives an error naming the valid names instead.
            pub fn from_name(name: &str) -> Option<Self> {
                match name {
                    $($name => Some($ty::$variant),)+
                    _ => None,
                }
            }

            /// The lowercase name, as [`Self::from_name`] reads it.
            pub fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name,)+
                }
            }
        }
    };
}

pub(crate) use named_options;

#[cfg(test)]
mod tests {
    use crate::classify::{SocpSolver, Surface};
    use crate::probability::Aggregation;
    use crate::query::QueryModel;
    use crate::uncertainty::RobustModel;

    /// Every value's name parses back to it, and `Display` writes the name.
    fn round_trip<T>(all: &[T])
    where
        T: Copy + PartialEq + std::fmt::Debug + std::fmt::Display + std::str::FromStr,
        T::Err: std::fmt::Debug,
    {
        assert!(!all.is_empty());
        for &v in all {
            let text = v.to_string();
            assert_eq!(text.parse::<T>().unwrap(), v, "{text}");
            assert_eq!(text, text.to_lowercase());
        }
    }

    #[test]
    fn names_round_trip() {
        round_trip(Surface::ALL);
        round_trip(SocpSolver::ALL);
        round_trip(Aggregation::ALL);
        round_trip(QueryModel::ALL);
        round_trip(RobustModel::ALL);
        assert_eq!(Surface::ALL, &[Surface::Linear, Surface::Quadric]);
        assert_eq!(Aggregation::ALL.len(), 4);
        assert_eq!(Surface::Quadric.to_string(), "quadric");
        assert_eq!(Aggregation::from_name("union"), Some(Aggregation::Union));
        assert_eq!(QueryModel::from_name("nope"), None);
    }

    #[test]
    fn unknown_names_list_the_valid_ones() {
        let msg = "cubic".parse::<Surface>().unwrap_err().to_string();
        assert_eq!(
            msg,
            "invalid input: unknown surface 'cubic'; valid names: 'linear', 'quadric'"
        );
        let msg = "mean".parse::<Aggregation>().unwrap_err().to_string();
        assert!(
            msg.contains("unknown aggregation 'mean'")
                && msg.contains("'surface', 'max', 'union', 'independent'"),
            "{msg}"
        );
        let msg = "Points".parse::<QueryModel>().unwrap_err().to_string();
        assert!(
            msg.contains("unknown model 'Points'; valid names: 'elements', 'points'"),
            "{msg}"
        );
        let msg = "".parse::<RobustModel>().unwrap_err().to_string();
        assert!(msg.contains("unknown robust_model ''"), "{msg}");
        let msg = "cvx".parse::<SocpSolver>().unwrap_err().to_string();
        assert!(msg.contains("'primal_dual', 'clarabel'"), "{msg}");
    }
}
