//! A panic of the LAZ decoder on corrupt compressed points is returned as a
//! format error and prints nothing: the panic hook in place before (here a
//! counting one) never sees it, while it still sees every other panic.
//!
//! Its own test binary: the test installs a panic hook before the first
//! `read_las` of the process.

use std::io::Cursor;
use std::panic::{catch_unwind, set_hook, take_hook};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use cloudprox::io::las::read_las;
use cloudprox::Error;
use las::point::Format;
use las::{Builder, Color, Point, Writer};

/// A LAZ file of 200 points on a ramp.
fn laz() -> Vec<u8> {
    let mut builder = Builder::from((1, 2));
    let mut format = Format::new(3).unwrap();
    format.is_compressed = true;
    builder.point_format = format;
    let header = builder.into_header().unwrap();
    let mut writer = Writer::new(Cursor::new(Vec::new()), header).unwrap();
    for i in 0..200 {
        let t = f64::from(i);
        writer
            .write_point(Point {
                x: t * 0.01,
                y: (t * 0.37).sin(),
                z: t * t * 1e-4,
                gps_time: Some(t),
                color: Some(Color::new(i as u16, 2, 3)),
                intensity: i as u16,
                ..Default::default()
            })
            .unwrap();
    }
    writer.into_inner().unwrap().into_inner()
}

#[test]
fn laz_decoder_panics_are_errors_and_silent() {
    let seen = Arc::new(AtomicUsize::new(0));
    let counter = Arc::clone(&seen);
    let default = take_hook();
    set_hook(Box::new(move |info| {
        counter.fetch_add(1, Ordering::SeqCst);
        default(info);
    }));

    let file = laz();
    let clean = read_las(&file, "ramp.laz").unwrap();
    assert_eq!(clean.points.len(), 200);
    // The compressed points start after the header, its records and the 8-byte
    // chunk table offset.
    let start = u32::from_le_bytes(file[96..100].try_into().unwrap()) as usize + 8;
    let mut decoder_failures = 0;
    let mut f = file.clone();
    for i in start..file.len() {
        if decoder_failures >= 3 {
            break;
        }
        for v in [0x00, 0xff] {
            let old = f[i];
            f[i] = v;
            match read_las(&f, "corrupt.laz") {
                Err(Error::Format { problem, .. }) if problem.contains("decoder failed") => {
                    decoder_failures += 1;
                }
                Err(Error::Format { .. }) | Ok(_) => {}
                Err(e) => panic!("expected a format error, got {e:?}"),
            }
            f[i] = old;
        }
    }
    // The decoder panics seen here are its `debug_assert!`s (laz 0.13,
    // `decoders.rs`): a release build of the tests may see none.
    assert!(
        decoder_failures > 0 || !cfg!(debug_assertions),
        "no corruption of the compressed points made the decoder panic"
    );
    assert_eq!(
        seen.load(Ordering::SeqCst),
        0,
        "a decoder panic reached the panic hook (and stderr)"
    );

    // Any other panic still reaches the hook that was there before.
    let _ = catch_unwind(|| panic!("an ordinary panic"));
    assert_eq!(seen.load(Ordering::SeqCst), 1);
}
