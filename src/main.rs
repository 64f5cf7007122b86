//! The `aloft` command line: parse, validate, call the library, render.
//!
//! Exit codes: 0 success, 1 infeasible mission or failed check, 2 bad input.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
