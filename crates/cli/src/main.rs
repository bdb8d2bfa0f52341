//! The `rpbrt` command-line renderer.
use std::process::ExitCode;

fn main() -> ExitCode {
    eprintln!("rpbrt: rendering is not built yet");
    ExitCode::FAILURE
}
