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

use clap::Parser;

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
    let cli = match args::Cli::try_parse() {
        Ok(c) => c,
        Err(e) if !e.use_stderr() => e.exit(), // --help, --version
        Err(e) => {
            // One line like every other error: clap's first line names the flag and the valid values.
            let text = e.render().to_string();
            let first = text
                .lines()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("invalid arguments");
            eprintln!("strata: {}", first.trim_start_matches("error: ").trim());
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
