#![no_main]
//! Fuzz target `pointcloud2_message`: see `cloudprox_fuzz::pointcloud2_message`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| cloudprox_fuzz::pointcloud2_message(data));
