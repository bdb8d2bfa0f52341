//! The render crate's integration tests, one binary (each test binary of
//! a release build is a whole-program link; one keeps `cargo test
//! --release` and CI quick). Each module is one subject; run one with
//! `cargo test -p rpbrt-render --test scenes <module>::`.

mod common;

mod data_fuzz;
mod displacement;
mod embree;
mod envmap;
mod integrators;
mod media;
mod mutation_fuzz;
mod observer;
mod v2_scenes;
mod v3_scenes;
