//! Rigid poses from and to 4x4 homogeneous matrices.

use crate::error::{Error, Result};
use crate::math::{Matrix3, Matrix4, Pose, Vector3};
use nalgebra::{Rotation3, Translation3, UnitQuaternion};

/// The rigid pose of a 4x4 homogeneous matrix `[R t; 0 0 0 1]`.
///
/// Rejects non-finite entries, a translation beyond
/// [`MAX_COORDINATE`](crate::cloud::MAX_COORDINATE), a last row other than
/// `[0, 0, 0, 1]`, and an `R` that is not a rotation (`|R^T R - I| > 1e-6` or `det R < 0`, i.e. scaling,
/// shear or a reflection). Rotations within that tolerance are re-orthonormalized.
pub fn pose_from_matrix(m: &Matrix4) -> Result<Pose> {
    if m.iter().any(|x| !x.is_finite()) {
        return Err(Error::invalid("pose has a NaN or infinite entry"));
    }
    let last = m.row(3);
    if (last[0].abs() + last[1].abs() + last[2].abs() + (last[3] - 1.0).abs()) > 1e-9 {
        return Err(Error::invalid(format!(
            "pose's last row must be [0, 0, 0, 1], got [{}, {}, {}, {}]",
            last[0], last[1], last[2], last[3]
        )));
    }
    let r: Matrix3 = m.fixed_view::<3, 3>(0, 0).into_owned();
    let err = (r.transpose() * r - Matrix3::identity()).amax();
    if err > 1e-6 || r.determinant() < 0.0 {
        return Err(Error::invalid(format!(
            "pose's upper-left 3x3 block is not a rotation (|R^T R - I| = {err:.2e}, det = {:.6})",
            r.determinant()
        )));
    }
    // Shepperd's method on the (near-)rotation, then renormalized: exact for a
    // rotation, the nearest unit quaternion for one within the tolerance.
    let rot = Rotation3::from_matrix_unchecked(r);
    let t: Vector3 = m.fixed_view::<3, 1>(0, 3).into_owned();
    if t.amax() > crate::cloud::MAX_COORDINATE {
        return Err(Error::invalid(format!(
            "pose's translation {:?} is beyond +-{:e} m",
            t.as_slice(),
            crate::cloud::MAX_COORDINATE
        )));
    }
    Ok(Pose::from_parts(
        Translation3::from(t),
        UnitQuaternion::new_normalize(*UnitQuaternion::from_rotation_matrix(&rot).quaternion()),
    ))
}

/// The 4x4 homogeneous matrix of a pose.
pub fn pose_to_matrix(pose: &Pose) -> Matrix4 {
    pose.to_homogeneous()
}

/// Checks a query's pose: finite, with a unit rotation and a translation within
/// [`MAX_COORDINATE`](crate::cloud::MAX_COORDINATE) (a `Pose` built from parts
/// can hold NaN or an overflowing translation; `what` names it in the error).
pub(crate) fn validate_pose(pose: &Pose, what: &str) -> Result<()> {
    let q = pose.rotation.quaternion();
    if !(q.coords.iter().all(|c| c.is_finite()) && (q.norm() - 1.0).abs() < 1e-6) {
        return Err(Error::invalid(format!(
            "{what}: the rotation is not a finite unit quaternion ({:?})",
            q.coords.as_slice()
        )));
    }
    let t = &pose.translation.vector;
    if t.iter().any(|c| !c.is_finite()) || t.amax() > crate::cloud::MAX_COORDINATE {
        return Err(Error::invalid(format!(
            "{what}: the translation {:?} is not finite or beyond +-{:e} m",
            t.as_slice(),
            crate::cloud::MAX_COORDINATE
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_rejections() {
        let p = Pose::new(Vector3::new(1.0, 2.0, 3.0), Vector3::new(0.3, -0.2, 1.1));
        let back = pose_from_matrix(&pose_to_matrix(&p)).unwrap();
        assert!((back.to_homogeneous() - p.to_homogeneous()).amax() < 1e-12);
        let mut scaled = pose_to_matrix(&p);
        scaled[(0, 0)] *= 2.0;
        assert!(pose_from_matrix(&scaled)
            .unwrap_err()
            .to_string()
            .contains("rotation"));
        let mut reflect = Matrix4::identity();
        reflect[(2, 2)] = -1.0;
        assert!(pose_from_matrix(&reflect).is_err());
        let mut bad_row = Matrix4::identity();
        bad_row[(3, 0)] = 1.0;
        assert!(pose_from_matrix(&bad_row)
            .unwrap_err()
            .to_string()
            .contains("last row"));
        let mut nan = Matrix4::identity();
        nan[(0, 3)] = f64::NAN;
        assert!(pose_from_matrix(&nan).is_err());
    }
}
