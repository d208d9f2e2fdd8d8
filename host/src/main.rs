//! The `pushbot` command.
fn main() -> std::process::ExitCode {
    pushbot::cli::main()
}
