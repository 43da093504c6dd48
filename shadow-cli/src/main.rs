//! `shadow`: the command-line front end of the exact BSP shadow toolkit
//! (see the library's documentation, `shadow_cli`).

fn main() -> std::process::ExitCode {
    shadow_cli::main()
}
