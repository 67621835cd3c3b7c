//! Shadow (veil) filter on a ray-cast depth image of a box in front of a wall,
//! with veil points interpolated across the box's silhouette.

use cloudprox::filter::{shadow_filter, ShadowSettings};
use cloudprox::io::Grid;
use cloudprox::prelude::*;
use cloudprox::sample::NormalRng;

const W: usize = 640;
const H: usize = 480;

/// Depth (z) along the ray through pixel (row, col): the front face of a box
/// at z = 1 (half sizes 0.3 x 0.2, centred on the axis, so its sides are
/// hidden), else a wall at z = 2.
fn depth(row: usize, col: usize) -> (f64, f64, f64) {
    let f = W as f64 / 2.0 / 30f64.to_radians().tan();
    let u = (col as f64 + 0.5 - W as f64 / 2.0) / f;
    let v = (row as f64 + 0.5 - H as f64 / 2.0) / f;
    let z = if u.abs() <= 0.3 && v.abs() <= 0.2 {
        1.0
    } else {
        2.0
    };
    (u, v, z)
}

/// Points (one per pixel, row-major), which are veil points, and which are box points.
fn scene(veil_width: usize, with_veil: bool) -> (Vec<Point3>, Vec<bool>, Vec<bool>) {
    let mut rng = NormalRng::new(3);
    let mut points = Vec::with_capacity(W * H);
    let (mut veil, mut on_box) = (Vec::new(), Vec::new());
    for row in 0..H {
        for col in 0..W {
            let (u, v, mut z) = depth(row, col);
            on_box.push(z == 1.0);
            // Distance in pixels to the nearest box pixel along the row or column.
            let mut near = None;
            if z == 2.0 && with_veil {
                for d in 1..=veil_width {
                    let hit = [
                        (row, col.wrapping_sub(d)),
                        (row, col + d),
                        (row.wrapping_sub(d), col),
                        (row + d, col),
                    ]
                    .iter()
                    .any(|&(r, c)| r < H && c < W && depth(r, c).2 == 1.0);
                    if hit {
                        near = Some(d);
                        break;
                    }
                }
            }
            veil.push(near.is_some());
            if let Some(d) = near {
                // A mixed pixel: depth interpolated from the box's to the wall's.
                let t = (d as f64 - 0.5 + 0.4 * (rng.uniform() - 0.5)) / veil_width as f64;
                z = 1.0 + t.clamp(0.1, 0.9);
            }
            let z = z + 0.0002 * rng.normal();
            points.push(Point3::new(u * z, v * z, z));
        }
    }
    (points, veil, on_box)
}

fn check(kept: &[u32], veil: &[bool], on_box: &[bool], what: &str) {
    let mut keep = vec![false; veil.len()];
    for &i in kept {
        keep[i as usize] = true;
    }
    assert!(kept.windows(2).all(|w| w[0] < w[1]));
    let veil_kept = (0..veil.len()).filter(|&i| veil[i] && keep[i]).count();
    assert_eq!(veil_kept, 0, "{what}: veil points kept");
    for (name, sel) in [
        (
            "box",
            (0..veil.len()).filter(|&i| on_box[i]).collect::<Vec<_>>(),
        ),
        (
            "wall",
            (0..veil.len())
                .filter(|&i| !on_box[i] && !veil[i])
                .collect(),
        ),
    ] {
        let k = sel.iter().filter(|&&i| keep[i]).count();
        assert!(
            k as f64 > 0.98 * sel.len() as f64,
            "{what}: {name} kept {k} of {}",
            sel.len()
        );
    }
}

#[test]
fn organized_veil_points_are_removed() {
    let grid = Grid {
        width: W,
        height: H,
        pixels: (0..(W * H) as u32).collect(),
    };
    for width in [1, 3] {
        let (points, veil, on_box) = scene(width, true);
        assert!(veil.iter().filter(|&&v| v).count() > 1000);
        let kept = shadow_filter(
            &points,
            &Point3::origin(),
            Some(&grid),
            &ShadowSettings::default(),
        )
        .unwrap();
        check(
            &kept,
            &veil,
            &on_box,
            &format!("organized, veil {width} px"),
        );
    }
}

#[test]
fn unorganized_veil_points_are_removed() {
    for width in [1, 3] {
        let (points, veil, on_box) = scene(width, true);
        let kept =
            shadow_filter(&points, &Point3::origin(), None, &ShadowSettings::default()).unwrap();
        check(
            &kept,
            &veil,
            &on_box,
            &format!("unorganized, veil {width} px"),
        );
    }
}

#[test]
fn organized_cloud_with_missing_pixels_and_no_veil() {
    // Drop every 7th pixel; no veil: at most the two rings at the depth step go.
    let (points, _, on_box) = scene(1, false);
    let keep: Vec<usize> = (0..points.len()).filter(|i| i % 7 != 0).collect();
    let sub: Vec<Point3> = keep.iter().map(|&i| points[i]).collect();
    let grid = Grid {
        width: W,
        height: H,
        pixels: keep.iter().map(|&i| i as u32).collect(),
    };
    let kept = shadow_filter(
        &sub,
        &Point3::origin(),
        Some(&grid),
        &ShadowSettings::default(),
    )
    .unwrap();
    let veil = vec![false; sub.len()];
    let on_box: Vec<bool> = keep.iter().map(|&i| on_box[i]).collect();
    check(&kept, &veil, &on_box, "missing pixels");
}
