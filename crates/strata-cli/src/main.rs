//! `strata` — layered screen-space global illumination, measured against ground truth.

mod args;
mod bench;
mod compare;
mod convert;
mod eval;
mod export;
mod info;
mod output;
mod reference;
mod render;
mod report_cmd;
mod soak;
mod techniques;
mod view;

use clap::{CommandFactory, FromArgMatches};

fn main() {
    // Output piped into `head` and closed early: end quietly like other command-line
    // tools instead of panicking on the broken pipe.
    #[cfg(unix)]
    // SAFETY: restores the default action of one signal before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_env("STRATA_LOG")
                .unwrap_or_else(|_| "warn,winit=error,egui_wgpu=error".into()),
        )
        .with_writer(std::io::stderr)
        .init();
    // Ctrl-C: outputs and cache entries are written to temporaries and renamed, so an
    // interrupt leaves the destinations untouched; remove the temporaries in flight.
    let _ = ctrlc::set_handler(|| {
        strata_scene::atomic::remove_in_flight();
        eprintln!("strata: interrupted: no output was written");
        std::process::exit(130);
    });
    let parsed = args::Cli::command()
        .try_get_matches()
        .and_then(|m| args::Cli::from_arg_matches(&m).map(|c| (c, m)));
    let cli = match parsed {
        Ok((mut c, m)) => {
            // which flags `render`, `soak`, `eval`, `reference` and `bench` were given, not
            // defaulted (`FrameArgs::unread_flags`, `EvalArgs::unread_flags`,
            // `ReferenceArgs::unread_flags`, the benches' layer flags)
            let given = |sub: &clap::ArgMatches| -> Vec<String> {
                sub.ids()
                    .filter(|id| sub.value_source(id.as_str()) == Some(clap::parser::ValueSource::CommandLine))
                    .map(|id| id.to_string())
                    .collect()
            };
            if let Some((_, sub)) = m.subcommand() {
                match &mut c.command {
                    args::Command::Render(a) => a.frame.given = given(sub),
                    args::Command::Soak(a) => a.frame.given = given(sub),
                    args::Command::Eval(a) => a.given = given(sub),
                    args::Command::Reference(a) => a.given = given(sub),
                    // `bench <what>`: the stage flags of the nested command
                    args::Command::Bench(b) => {
                        if let (Some(stage), Some((_, what))) = (b.what.stage_mut(), sub.subcommand()) {
                            stage.given = given(what);
                        }
                    }
                    _ => {}
                }
            }
            c
        }
        Err(e) if !e.use_stderr() => e.exit(), // --help, --version
        Err(e) => {
            eprintln!("strata: {}", one_line(&e.render().to_string()));
            std::process::exit(2);
        }
    };
    let result = match cli.command {
        args::Command::Info(a) => info::run(&a),
        args::Command::Render(a) => render::run(&a),
        args::Command::Reference(a) => reference::run(&a),
        args::Command::Bench(a) => bench::run(&a),
        args::Command::Soak(a) => soak::run(&a),
        args::Command::Techniques(a) => techniques::run(&a),
        args::Command::Eval(a) => eval::run(&a),
        args::Command::Report(a) => report_cmd::run(&a),
        args::Command::ExportScene(a) => export::run(&a),
        args::Command::Compare(a) => compare::run(&a),
        args::Command::View(a) => view::run(&a),
    };
    if let Err(e) = result {
        // One line: what is wrong and what is valid.
        let msg = format!("{e:#}").replace('\n', " ");
        eprintln!("strata: error: {msg}");
        std::process::exit(1);
    }
}

/// A clap error on one line, like every other error: its first line, then what follows it
/// up to the usage (the missing flags, `[possible values: …]`, a tip naming a similar flag).
pub(crate) fn one_line(text: &str) -> String {
    let mut lines = text
        .lines()
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .map(str::trim)
        .filter(|l| !l.is_empty());
    let first = lines
        .next()
        .unwrap_or("invalid arguments")
        .trim_start_matches("error: ")
        .to_string();
    let rest: Vec<&str> = lines.collect();
    match (rest.is_empty(), first.ends_with(':')) {
        (true, _) => first,
        // a list: "the following required arguments were not provided: --kind <KIND>, --out <OUT>"
        (false, true) => format!("{first} {}", rest.join(", ")),
        (false, false) => format!("{first}; {}", rest.join("; ")),
    }
}

#[cfg(test)]
mod tests {
    use super::one_line;

    #[test]
    fn clap_errors_keep_the_flags_and_values_on_one_line() {
        let missing = "error: the following required arguments were not provided:\n  --kind <KIND>\n  --out <OUT>\n\nUsage: strata reference --kind <KIND> --out <OUT>\n\nFor more information, try '--help'.\n";
        assert_eq!(
            one_line(missing),
            "the following required arguments were not provided: --kind <KIND>, --out <OUT>"
        );
        let value = "error: invalid value 'foo' for '--kind <KIND>'\n  [possible values: ao, gi]\n\nFor more information, try '--help'.\n";
        assert_eq!(
            one_line(value),
            "invalid value 'foo' for '--kind <KIND>'; [possible values: ao, gi]"
        );
        assert_eq!(one_line(""), "invalid arguments");
    }
}
