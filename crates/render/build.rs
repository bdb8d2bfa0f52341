//! Generates the RGB to spectrum coefficient tables (Jakob and Hanika 2019)
//! for the built-in colour spaces into `OUT_DIR`, where
//! `src/spectrum/colorspace.rs` embeds them.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

#[path = "src/spectrum/data/cie.rs"]
#[allow(dead_code)]
mod cie;
#[path = "src/spectrum/rgb2spec_opt.rs"]
mod rgb2spec_opt;

/// Table resolution per axis, as pbrt-v4.
const RES: usize = 64;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/spectrum/rgb2spec_opt.rs");
    println!("cargo:rerun-if-changed=src/spectrum/data/cie.rs");
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut log = String::new();
    for (name, file) in [
        ("srgb", "rgbspec_srgb.bin"),
        ("dci-p3", "rgbspec_dci_p3.bin"),
        ("rec2020", "rgbspec_rec2020.bin"),
        ("aces2065-1", "rgbspec_aces2065_1.bin"),
    ] {
        let start = Instant::now();
        let gamut = rgb2spec_opt::gamut(name).expect("built-in gamut");
        let (z, coeffs) = rgb2spec_opt::optimize(
            &gamut,
            [&cie::CIE_X, &cie::CIE_Y, &cie::CIE_Z],
            RES,
            threads,
        );
        let mut bytes = Vec::with_capacity(4 * (z.len() + coeffs.len()));
        for v in z.iter().chain(&coeffs) {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let mut f = std::fs::File::create(out_dir.join(file)).expect("create table file");
        f.write_all(&bytes).expect("write table file");
        log += &format!(
            "{name}: {:.2} s on {threads} threads\n",
            start.elapsed().as_secs_f64()
        );
    }
    std::fs::write(out_dir.join("rgbspec_timing.txt"), log).expect("write timing");
}
