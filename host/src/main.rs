//! The `pushbot` command.
fn main() -> std::process::ExitCode {
    // The Rust runtime ignores SIGPIPE, so `println!` into a pipe whose reader has gone
    // (`pushbot … | head -1`) panics. Restore the signal's default, as every Unix filter has
    // it: the process ends quietly. Sockets are unaffected (std writes them with
    // MSG_NOSIGNAL, so the sim camera still sees EPIPE), and ptys give EIO, not SIGPIPE.
    sigpipe::reset();
    pushbot::cli::main()
}
