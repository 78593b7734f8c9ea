//! The `luxeval` binary: everything is in this crate's library (`src/lib.rs`).

fn main() -> std::process::ExitCode {
    luxeval_cli::main()
}
