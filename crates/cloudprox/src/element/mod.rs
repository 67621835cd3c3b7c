//! Surface elements: the surfaces a cloud's points sample, at the resolution the
//! data supports.
//!
//! `n` independent noisy samples of a flat patch locate it along its normal with
//! standard deviation `sigma / sqrt(n)`, not `sigma`. A cloud's points are
//! therefore grouped, once per cloud and in its own frame, into *surface
//! elements*: groups that fit a plane within their own noise. The groups come from
//! a top-down split (at the median along the largest principal axis, or, for
//! segmentation `k > 0` ([`ElementSettings::segmentation`]), at a quantile
//! between 40% and 60% drawn from `k` and the group; or between
//! two surfaces where the points along the normal fall into two groups further
//! apart than the noise, as the two faces of a thin plate do); a group is an
//! element as soon as a residual test at the significance level
//! [`ElementSettings::significance`], a curvature rule and a coverage test
//! accept it:
//!
//! 1. **Residual test.** A quadric height field `h(u, v)` over the group's
//!    principal plane is fitted by weighted least squares, each point weighted by
//!    its sensor variance along the normal. The weighted residual sum follows a
//!    chi-square law with `m - 6` degrees of freedom when the points sample one
//!    smooth surface with the stated noise; two faces, an edge or a corner make
//!    it too large. Each point's standardized residual must also stay below
//!    the largest of `m` standard normals (a Bonferroni bound): one point far
//!    off a surface the others fit adds less to the sum than the sum's own
//!    spread over hundreds of points.
//! 2. **Curvature rule.** The element's surface is a plane, so the group is
//!    split unless the plane describes its points' surface as well as the
//!    quadric is expected to: the quadric's three curvature coefficients,
//!    against their covariance from the fit (a Wald statistic `W`), must keep
//!    `W <= 6` (Mallows' Cp: the two fits' estimates of their expected
//!    squared errors differ by `W - 2 x 3`). A group too small for both
//!    halves to be elements (fewer than twice
//!    [`ElementSettings::min_points`]) would leave single points with their
//!    full noise: it splits only on a significant
//!    curvature (`W` above the chi-square quantile at the significance
//!    level). A group larger than the surface's curvature scale at this
//!    noise is split. So elements are large where the surface is flat or the
//!    noise is high, and shrink with curvature and with falling noise; no
//!    threshold is tuned to a scene. (A significance test here, `W` against
//!    11.3 at 1%, kept planes whose sag was several times their stated
//!    uncertainty.)
//!
//! 3. **Coverage test.** The points cover the rectangle the element claims
//!    (its tangents along the sides of the smallest rectangle holding them, its
//!    extent their sampled edges with the noise taken out, see
//!    [`SurfaceElement::extent`]): at least half of its cells of twice the
//!    sampling spacing hold a point, and no strip of empty cells runs across
//!    it. Two coplanar patches apart pass the first two together, but the
//!    plane between them was never sampled.
//!
//! An accepted element keeps its mean, normal and tangents, its extent, and the
//! covariance of its mean (`sum(Sigma_i) / m^2` for independent noise;
//! [`ElementSettings::noise_correlation`] for sensors whose noise is correlated
//! between neighbouring points) and of its plane's slopes. Groups of fewer than
//! [`ElementSettings::min_points`] (10) points that still fail keep their points
//! as they are (single-point elements): at sharp edges, corners, outliers and
//! where the sampling is sparse against the curvature, the query falls back to
//! the points. (Admitting groups of 4-9 points on the plane's residual test
//! alone made elements of four sparse points span 40 cm on the real Kinect
//! frame, and false collisions at 7 sigma.)
//!
//! The median splits cut flat faces apart wherever an edge or a second face
//! shared a group higher up; a bottom-up pass then merges neighbouring elements
//! (and single points) whose union still passes the residual test and the
//! curvature rule.
//!
//! An element keeps its fitted plane (weighted least squares over its
//! principal plane: curvature did not pay for itself) and the covariance of the
//! fit, so any point of its surface comes with the variance of its height, the
//! slopes' uncertainty included
//! ([`SurfaceElement::surface_point`]). In a query it is represented by five
//! samples of that surface ([`SurfaceElements::samples`]): over its mean and at
//! the ends of its points' range along each tangent; a large element also by
//! a grid of six sampling spacings over where it was sampled.
//!
//! Each element also has a *hull*: its fitted surface at the four corners of
//! the extent (the surface is a plane over the extent, so it lies in their
//! convex hull), the largest variance of its height and half its sampling
//! spacing; a hierarchy over the hulls, built once per cloud, tells a query at
//! once when no element of one cloud can come within the noise's reach of the
//! other's, without building near regions (two 10 000-point spheres at 1 mm
//! of noise, 6 sigma apart: 0.03 ms instead of 0.3-0.4 ms).

mod element_build;
mod element_fit;
mod element_merge;
mod element_reach;
mod element_samples;
mod element_types;

pub use element_fit::chi_square_quantile;
pub(crate) use element_reach::{across_normal, hull_gap, surfaces_may_reach, Hull, HALF_SPACING};
pub(crate) use element_types::{height_row, MemberChunk};
pub use element_types::{ElementSettings, FootprintPoint, SurfaceElement, SurfaceElements};
