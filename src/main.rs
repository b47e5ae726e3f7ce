//! `radiosity`: solve, render, view and export diffuse global illumination by progressive shooting.

mod alloc;
mod bench_cmd;
mod bench_real;
mod compare_cmd;
mod comparison;
mod errors;
mod export_cmd;
mod false_colour_cmd;
mod grid_cmd;
mod info_cmd;
mod interrupt;
mod lighting_cmd;
mod load_scene;
mod output;
mod picture_opts;
mod prepare;
mod progress;
mod reference_run;
mod render_cmd;
mod report_html;
mod solve_cmd;
mod solve_opts;
mod tonemap_cmd;
mod verify_cmd;
mod view_cmd;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Counts heap bytes so `radiosity bench` can report peak memory per case.
#[global_allocator]
static HEAP: alloc::Counting = alloc::Counting;

/// Progressive-refinement radiosity renderer (the shooting method).
#[derive(Parser)]
#[command(name = "radiosity", version, about, long_about = None)]
struct Cli {
    /// No progress on stderr (results, notes and warnings still print).
    #[arg(long, short = 'q', global = true)]
    quiet: bool,
    /// Seconds between progress lines when stderr is not a terminal (tests set it short).
    #[arg(long, global = true, hide = true, default_value_t = progress::LOG_INTERVAL.as_secs_f64())]
    progress_interval: f64,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene headless and report per-object radiosity.
    Solve(solve_cmd::SolveArgs),
    /// Print counts, areas, emitted power and warnings for a scene.
    Info(info_cmd::InfoArgs),
    /// Run the fixed benchmark cases and print figures.
    Bench(bench_cmd::BenchArgs),
    /// Solve a scene and ray cast it to a tone-mapped PNG (and linear EXR / PFM).
    Render(render_cmd::RenderArgs),
    /// Tone map a linear picture (.exr or .pfm) to PNG again, without solving.
    Tonemap(tonemap_cmd::TonemapArgs),
    /// Open a window that solves the scene live while you fly through it.
    View(view_cmd::ViewArgs),
    /// Solve a scene and write the lit mesh (glTF, GLB, PLY) with baked colours, and lightmaps.
    Export(export_cmd::ExportArgs),
    /// Solve a photometric scene and write its calculation grids: lux as CSV, false-colour
    /// pictures and an HTML report.
    Grid(grid_cmd::GridArgs),
    /// Solve a scene and check it against an independent Monte Carlo reference, per object.
    Verify(verify_cmd::VerifyArgs),
    /// Compare two linear pictures (.exr / .pfm): per-channel errors and a difference picture.
    Compare(compare_cmd::CompareArgs),
}

fn main() -> ExitCode {
    alloc::keep_freed_memory();
    output::start_clock();
    let cli = Cli::parse();
    progress::set_quiet(cli.quiet);
    if cli.progress_interval.is_finite() && cli.progress_interval > 0.0 {
        progress::set_log_interval(std::time::Duration::from_secs_f64(cli.progress_interval));
    }
    let result = match cli.command {
        Command::Solve(a) => solve_cmd::run(a),
        Command::Info(a) => info_cmd::run(a),
        Command::Bench(a) => bench_cmd::run(a),
        Command::Render(a) => render_cmd::run(a),
        Command::Tonemap(a) => tonemap_cmd::run(a),
        Command::View(a) => view_cmd::run(a),
        Command::Export(a) => export_cmd::run(a),
        Command::Grid(a) => grid_cmd::run(a),
        Command::Verify(a) => verify_cmd::run(a),
        Command::Compare(a) => compare_cmd::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // A reader that stopped reading (`| head`) is not an error to report.
        Err(e) if output::is_broken_pipe(&e) => ExitCode::from(output::BROKEN_PIPE_EXIT),
        // What the run had when Ctrl-C stopped it is out; the status says it was stopped.
        Err(e) if e.is::<interrupt::Interrupted>() => {
            let _ = output::note(format_args!("{e}"));
            ExitCode::from(interrupt::INTERRUPTED_EXIT)
        }
        Err(e) => {
            // Nowhere left to report a failure to write the report; the exit code still says it.
            let _ = output::note(format_args!("error: {}", radiosity_core::one_line(e.as_ref())));
            ExitCode::from(errors::exit_code(&e))
        }
    }
}
