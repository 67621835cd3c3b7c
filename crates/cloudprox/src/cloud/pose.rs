//! Rigid poses: from and to 4x4 homogeneous matrices, and the constructors every
//! caller (Rust and Python) shares: translation, quaternion, roll-pitch-yaw,
//! rotation vector, `look_at` and seeded uniformly random rotations.
//!
//! Conventions (one place for all of them):
//! - quaternions are `(w, x, y, z)`, scalar first, and are normalised (a zero or
//!   non-finite quaternion is an error);
//! - roll-pitch-yaw is ROS/URDF's: rotations about the *fixed* x, then y, then z
//!   axes, `R = Rz(yaw) Ry(pitch) Rx(roll)`;
//! - a rotation vector is the axis times the angle in radians;
//! - [`pose_look_at`] gives a camera's optical frame (x right, y down, z forward
//!   towards the target), the frame the depth-camera models use.

use crate::error::{Error, Result};
use crate::math::{Matrix3, Matrix4, Point3, Pose, Vector3};
use crate::sample::NormalRng;
use crate::Real;
use nalgebra::{Rotation3, Translation3, Unit, UnitQuaternion};

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

/// `v` if finite and within [`MAX_COORDINATE`](crate::cloud::MAX_COORDINATE);
/// otherwise an error naming `what`.
fn checked_vector(v: &Vector3, what: &str) -> Result<Vector3> {
    if v.iter().any(|c| !c.is_finite()) {
        return Err(Error::invalid(format!(
            "{what} has a NaN or infinite entry: {:?}",
            v.as_slice()
        )));
    }
    if v.amax() > crate::cloud::MAX_COORDINATE {
        return Err(Error::invalid(format!(
            "{what} {:?} is beyond +-{:e} m",
            v.as_slice(),
            crate::cloud::MAX_COORDINATE
        )));
    }
    Ok(*v)
}

/// Finite angles (radians) or an error naming `what`.
fn checked_angles(v: &Vector3, what: &str) -> Result<Vector3> {
    if v.iter().any(|c| !c.is_finite()) {
        return Err(Error::invalid(format!(
            "{what} has a NaN or infinite entry: {:?}",
            v.as_slice()
        )));
    }
    Ok(*v)
}

/// The pure translation by `translation` (metres).
///
/// # Errors
/// `InvalidInput` naming `translation` if it is not finite or beyond
/// [`MAX_COORDINATE`](crate::cloud::MAX_COORDINATE).
pub fn pose_from_translation(translation: &Vector3) -> Result<Pose> {
    let t = checked_vector(translation, "translation")?;
    Ok(Pose::from_parts(
        Translation3::from(t),
        UnitQuaternion::identity(),
    ))
}

/// The unit quaternion of `(w, x, y, z)` (scalar first), normalised.
///
/// # Errors
/// `InvalidInput` naming `quaternion` if an entry is not finite or the
/// quaternion is zero (norm below `1e-12`).
pub fn unit_quaternion(wxyz: [Real; 4]) -> Result<UnitQuaternion<Real>> {
    if wxyz.iter().any(|c| !c.is_finite()) {
        return Err(Error::invalid(format!(
            "quaternion (w, x, y, z) has a NaN or infinite entry: {wxyz:?}"
        )));
    }
    let [w, x, y, z] = wxyz;
    let q = nalgebra::Quaternion::new(w, x, y, z);
    if q.norm() < 1e-12 {
        return Err(Error::invalid(format!(
            "quaternion (w, x, y, z) is zero: {wxyz:?}; a rotation needs a non-zero quaternion"
        )));
    }
    Ok(UnitQuaternion::new_normalize(q))
}

/// The pose rotating by the quaternion `wxyz` = `(w, x, y, z)` (scalar first,
/// normalised here), then translating by `translation`.
///
/// # Errors
/// `InvalidInput` naming `quaternion` (non-finite or zero) or `translation`.
pub fn pose_from_quaternion(translation: &Vector3, wxyz: [Real; 4]) -> Result<Pose> {
    let t = checked_vector(translation, "translation")?;
    Ok(Pose::from_parts(
        Translation3::from(t),
        unit_quaternion(wxyz)?,
    ))
}

/// The pose rotating by roll-pitch-yaw angles (radians), then translating by
/// `translation`.
///
/// The convention is ROS/URDF's `rpy`: roll about the fixed x axis, then pitch
/// about the fixed y axis, then yaw about the fixed z axis, i.e.
/// `R = Rz(yaw) Ry(pitch) Rx(roll)` (the same as intrinsic z-y'-x'').
///
/// # Errors
/// `InvalidInput` naming `rpy` (non-finite) or `translation`.
pub fn pose_from_rpy(translation: &Vector3, rpy: &Vector3) -> Result<Pose> {
    let t = checked_vector(translation, "translation")?;
    let a = checked_angles(rpy, "rpy")?;
    Ok(Pose::from_parts(
        Translation3::from(t),
        UnitQuaternion::from_euler_angles(a.x, a.y, a.z),
    ))
}

/// The pose rotating by the rotation vector `rotation_vector` (unit axis times
/// the angle in radians, right-handed), then translating by `translation`.
///
/// # Errors
/// `InvalidInput` naming `rotation_vector` (non-finite) or `translation`.
pub fn pose_from_rotation_vector(translation: &Vector3, rotation_vector: &Vector3) -> Result<Pose> {
    let t = checked_vector(translation, "translation")?;
    let v = checked_angles(rotation_vector, "rotation_vector")?;
    Ok(Pose::from_parts(
        Translation3::from(t),
        UnitQuaternion::from_scaled_axis(v),
    ))
}

/// A camera at `eye` looking at `target`: its optical frame in the world.
///
/// The camera convention is the optical frame of ROS (`REP 103`, `*_optical_frame`)
/// and OpenCV, the one [`DepthCamera`](crate::uncertainty::DepthCamera) models use: z forward
/// (from `eye` towards `target`), x to the image's right, y down in the image.
/// "Up" in the image is as close to `up` as possible: x = z x up (normalised),
/// y = z x x.
///
/// # Errors
/// `InvalidInput` naming the argument if `eye`, `target` or `up` is not finite
/// (or beyond [`MAX_COORDINATE`](crate::cloud::MAX_COORDINATE)), `target` equals
/// `eye`, `up` is zero, or the viewing direction is parallel to `up`.
pub fn pose_look_at(eye: &Point3, target: &Point3, up: &Vector3) -> Result<Pose> {
    let e = checked_vector(&eye.coords, "eye")?;
    let t = checked_vector(&target.coords, "target")?;
    let up = checked_vector(up, "up")?;
    let forward = t - e;
    let Some(z) = forward.try_normalize(1e-12) else {
        return Err(Error::invalid(format!(
            "target {:?} is the eye's position; a camera must look somewhere else",
            t.as_slice()
        )));
    };
    let Some(up) = up.try_normalize(1e-12) else {
        return Err(Error::invalid("up is zero; give the world's up direction"));
    };
    let Some(x) = z.cross(&up).try_normalize(1e-9) else {
        return Err(Error::invalid(format!(
            "up {:?} is parallel to the viewing direction {:?}; give another up",
            up.as_slice(),
            z.as_slice()
        )));
    };
    let y = z.cross(&x);
    let rot = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, z]));
    Ok(Pose::from_parts(
        Translation3::from(e),
        UnitQuaternion::from_rotation_matrix(&rot),
    ))
}

/// `n` rotations drawn uniformly (Haar measure) from the rotation group: unit
/// quaternions of four standard normals (normalised), from the core's seeded
/// generator ([`NormalRng`]). The same `seed` gives the same rotations on every
/// platform.
pub fn random_rotations(n: usize, seed: u64) -> Vec<UnitQuaternion<Real>> {
    let mut rng = NormalRng::new(seed);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let q = nalgebra::Quaternion::new(rng.normal(), rng.normal(), rng.normal(), rng.normal());
        // A draw of norm ~0 has probability ~0; skip it rather than divide by it.
        if let Some(u) = Unit::try_new(q, 1e-9) {
            out.push(u);
        }
    }
    out
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

    fn rot(p: &Pose) -> Matrix3 {
        p.rotation.to_rotation_matrix().into_inner()
    }

    fn close(a: &Matrix3, b: &Matrix3) -> bool {
        (a - b).amax() < 1e-12
    }

    #[test]
    fn translation_only_moves() {
        let t = Vector3::new(1.0, -2.0, 0.5);
        let p = pose_from_translation(&t).unwrap();
        assert_eq!(p.translation.vector, t);
        assert!(close(&rot(&p), &Matrix3::identity()));
        let err = pose_from_translation(&Vector3::new(f64::NAN, 0.0, 0.0)).unwrap_err();
        assert!(err.to_string().contains("translation"), "{err}");
        assert!(pose_from_translation(&Vector3::new(2e9, 0.0, 0.0)).is_err());
    }

    #[test]
    fn quarter_turn_about_z_maps_x_to_y_in_every_form() {
        let h = std::f64::consts::FRAC_PI_2;
        let zero = Vector3::zeros();
        let s = 0.5f64.sqrt();
        let forms = [
            pose_from_quaternion(&zero, [s, 0.0, 0.0, s]).unwrap(),
            // Not normalised: scaled by 3.
            pose_from_quaternion(&zero, [3.0 * s, 0.0, 0.0, 3.0 * s]).unwrap(),
            pose_from_rpy(&zero, &Vector3::new(0.0, 0.0, h)).unwrap(),
            pose_from_rotation_vector(&zero, &Vector3::new(0.0, 0.0, h)).unwrap(),
        ];
        for p in &forms {
            let y = p * Point3::new(1.0, 0.0, 0.0);
            assert!((y - Point3::new(0.0, 1.0, 0.0)).norm() < 1e-12, "{y}");
        }
    }

    #[test]
    fn quaternion_rejects_zero_and_nan() {
        let zero = Vector3::zeros();
        let err = pose_from_quaternion(&zero, [0.0; 4])
            .unwrap_err()
            .to_string();
        assert!(err.contains("quaternion") && err.contains("zero"), "{err}");
        let err = pose_from_quaternion(&zero, [1.0, f64::NAN, 0.0, 0.0])
            .unwrap_err()
            .to_string();
        assert!(err.contains("quaternion"), "{err}");
    }

    #[test]
    fn rpy_is_fixed_axis_x_then_y_then_z_and_agrees_with_quaternions() {
        let (r, p, y) = (0.3, -0.2, 1.1);
        let pose = pose_from_rpy(&Vector3::new(1.0, 2.0, 3.0), &Vector3::new(r, p, y)).unwrap();
        let about = |axis: Vector3, a: Real| {
            let h = 0.5 * a;
            let u = axis * h.sin();
            pose_from_quaternion(&Vector3::zeros(), [h.cos(), u.x, u.y, u.z]).unwrap()
        };
        let composed = about(Vector3::z(), y) * about(Vector3::y(), p) * about(Vector3::x(), r);
        assert!(close(&rot(&pose), &rot(&composed)));
        // The URDF closed form, R = Rz(yaw) Ry(pitch) Rx(roll).
        let (cr, sr, cp, sp, cy, sy) = (r.cos(), r.sin(), p.cos(), p.sin(), y.cos(), y.sin());
        let urdf = Matrix3::new(
            cy * cp,
            cy * sp * sr - sy * cr,
            cy * sp * cr + sy * sr,
            sy * cp,
            sy * sp * sr + cy * cr,
            sy * sp * cr - cy * sr,
            -sp,
            cp * sr,
            cp * cr,
        );
        assert!(close(&rot(&pose), &urdf));
        assert_eq!(pose.translation.vector, Vector3::new(1.0, 2.0, 3.0));
        let err = pose_from_rpy(&Vector3::zeros(), &Vector3::new(0.0, f64::INFINITY, 0.0))
            .unwrap_err()
            .to_string();
        assert!(err.contains("rpy"), "{err}");
    }

    #[test]
    fn rotation_vector_and_quaternion_round_trip() {
        for v in [
            Vector3::new(0.3, -0.2, 1.1),
            Vector3::new(-2.0, 0.5, 0.1),
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1e-9, 0.0, 0.0),
        ] {
            let p = pose_from_rotation_vector(&Vector3::zeros(), &v).unwrap();
            let q = p.rotation.quaternion();
            let back = pose_from_quaternion(&Vector3::zeros(), [q.w, q.i, q.j, q.k]).unwrap();
            assert!(close(&rot(&p), &rot(&back)));
            assert!((back.rotation.scaled_axis() - v).norm() < 1e-12, "{v}");
        }
        assert!(
            pose_from_rotation_vector(&Vector3::zeros(), &Vector3::new(f64::NAN, 0.0, 0.0))
                .unwrap_err()
                .to_string()
                .contains("rotation_vector")
        );
    }

    #[test]
    fn look_at_points_the_optical_axis_at_the_target() {
        let eye = Point3::new(0.0, -0.55, 1.55);
        let target = Point3::new(0.0, 0.3, 0.8);
        let p = pose_look_at(&eye, &target, &Vector3::z()).unwrap();
        assert_eq!(p.translation.vector, eye.coords);
        // The camera's +z axis, and the target in the camera frame, lie on it.
        let axis = p.rotation * Vector3::z();
        assert!((axis - (target - eye).normalize()).norm() < 1e-12);
        let local = p.inverse() * target;
        assert!(local.x.abs() < 1e-12 && local.y.abs() < 1e-12 && local.z > 0.0);
        // Image y points down: against the world's up.
        assert!((p.rotation * Vector3::y()).dot(&Vector3::z()) < 0.0);
        // x right: x = z x up (looking along +y with z up, right is +x).
        assert!((p.rotation * Vector3::x()).dot(&Vector3::x()) > 0.99);
        assert!(validate_pose(&p, "look_at").is_ok());
        for (t, up, what) in [
            (eye, Vector3::z(), "target"),
            (target, Vector3::zeros(), "up"),
            (Point3::new(0.0, -0.55, 0.0), Vector3::z(), "parallel"),
        ] {
            let err = pose_look_at(&eye, &t, &up).unwrap_err().to_string();
            assert!(err.contains(what), "{err}");
        }
    }

    #[test]
    fn random_rotations_are_seeded_unit_and_spread() {
        let a = random_rotations(2000, 7);
        assert_eq!(a, random_rotations(2000, 7));
        assert_ne!(a[0], random_rotations(1, 8)[0]);
        // Uniform on SO(3): the rotated x axis is uniform on the sphere, so each
        // coordinate has mean 0 and variance 1/3.
        let xs: Vec<Vector3> = a.iter().map(|q| q * Vector3::x()).collect();
        for k in 0..3 {
            let mean = xs.iter().map(|v| v[k]).sum::<Real>() / 2000.0;
            let var = xs.iter().map(|v| v[k] * v[k]).sum::<Real>() / 2000.0;
            assert!(
                mean.abs() < 0.05 && (var - 1.0 / 3.0).abs() < 0.03,
                "{mean} {var}"
            );
        }
        for q in &a {
            assert!((q.quaternion().norm() - 1.0).abs() < 1e-12);
        }
    }
}
