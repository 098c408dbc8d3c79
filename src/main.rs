//! The `swarmmap` command line: parses options, calls the library, maps outcomes to exit
//! codes (0 success, 1 failure, 2 invalid input).

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
