//! What the user reads is what the program does: every `--help` text is printed, and every
//! command line in the READMEs' `sh` blocks is run against the built binary (with small
//! budgets), checked to parse, or, for what is not `radiosity` (setup, cargo, Python), checked
//! against an explicit list. A README command this file does not know fails the test, so a new
//! one gets covered when it is written.

use std::path::Path;
use std::process::{Command, Output, Stdio};

/// The commands whose first argument is a SCENE; their help must name every form it takes.
const SCENE_COMMANDS: [&str; 7] = ["solve", "info", "render", "view", "export", "grid", "verify"];

/// The READMEs and reference pages whose `sh` blocks are run.
const READMES: [&str; 7] = [
    "README.md",
    "crates/radiosity_viewer/README.md",
    "docs/CLI.md",
    "docs/FORMAT.md",
    "docs/ACCURACY.md",
    "docs/PERFORMANCE.md",
    "docs/ARCHITECTURE.md",
];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `radiosity ARGS` in `dir`, without a display (a window cannot open by accident) and with
/// stdin closed.
fn radiosity(args: &[String], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(args)
        .current_dir(dir)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .stdin(Stdio::null())
        .output()
        .expect("run radiosity")
}

fn text(o: &Output) -> (String, String) {
    (String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// The subcommands `radiosity --help` lists (without `help` itself).
fn subcommands() -> Vec<String> {
    let o = radiosity(&["--help".into()], root());
    let (out, err) = text(&o);
    assert!(o.status.success() && !out.trim().is_empty(), "radiosity --help: {err}");
    let listed: Vec<String> = out
        .lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(str::to_owned))
        .filter(|c| c != "help")
        .collect();
    assert!(listed.len() >= SCENE_COMMANDS.len(), "no command list in:\n{out}");
    listed
}

/// Every command's help prints, and each command that takes a SCENE says every form of it: a
/// scene file, a model file and each built-in name.
#[test]
fn every_help_text_prints_and_names_the_scene_forms() {
    let mut with_scene = Vec::new();
    for command in subcommands() {
        let o = radiosity(&[command.clone(), "--help".into()], root());
        let (out, err) = text(&o);
        assert!(o.status.success(), "radiosity {command} --help: {err}");
        assert!(out.contains(&format!("Usage: radiosity {command}")), "radiosity {command} --help:\n{out}");
        if out.lines().any(|l| l.starts_with("Usage:") && l.contains("SCENE")) {
            with_scene.push(command.clone());
            for form in [".toml", ".obj with its .mtl", ".gltf", ".glb"]
                .into_iter()
                .chain(radiosity_io::BUILTIN_SCENES.iter().copied())
            {
                assert!(out.contains(form), "radiosity {command} --help does not name {form}:\n{out}");
            }
        }
    }
    assert_eq!(with_scene, SCENE_COMMANDS, "the commands that take a SCENE");
}

/// The command lines of the READMEs' `sh` blocks, comments removed, split at `&&`: `(README,
/// block number, command)`.
fn readme_commands() -> Vec<(String, usize, String)> {
    let mut commands = Vec::new();
    let mut block = 0;
    for readme in READMES {
        let doc = std::fs::read_to_string(root().join(readme)).unwrap();
        let mut in_sh = false;
        for line in doc.lines() {
            match line.trim() {
                "```sh" => {
                    in_sh = true;
                    block += 1;
                }
                "```" => in_sh = false,
                _ if in_sh => {
                    let line = line.split(" #").next().unwrap().trim();
                    assert!(!line.ends_with('\\'), "{readme}: continued lines are not read: {line}");
                    for command in line.split("&&").map(str::trim).filter(|c| !c.is_empty()) {
                        commands.push((readme.to_owned(), block, command.to_owned()));
                    }
                }
                _ => {}
            }
        }
    }
    commands
}

/// Sets `option` to `value` in `args`, replacing the value the README gives, so a budget
/// never repeats an option (which the command would refuse).
fn set(args: &mut Vec<String>, option: &str, value: &str) {
    match args.iter().position(|a| a == option) {
        Some(i) => args[i + 1] = value.to_owned(),
        None => args.extend([option.to_owned(), value.to_owned()]),
    }
}

/// What is done with a README's `radiosity` command.
enum Check {
    /// Run it (with budgets) and expect success.
    Run,
    /// Run it without a display: the scene loads and the options are checked (exit code 2
    /// otherwise), then the window cannot open (exit code 1, the no-display message). The
    /// window itself is tested in tests/suite/viewer.rs.
    NoWindow,
    /// Too long for a test (minutes): its options are checked to parse (`--help` after them).
    Parse,
}

/// The small budgets of a README command, and how it is checked; `None` for a subcommand
/// this test does not know.
fn budget(args: &mut Vec<String>) -> Option<Check> {
    let small_solve = |args: &mut Vec<String>| set(args, "--max-shots", "5");
    let small_picture = |args: &mut Vec<String>| {
        set(args, "--width", "24");
        set(args, "--height", "16");
        set(args, "--spp", "1");
        if args.iter().any(|a| a == "--reference") {
            set(args, "--reference-spp", "2");
        }
    };
    Some(match args[0].as_str() {
        "solve" | "export" | "grid" => {
            small_solve(args);
            Check::Run
        }
        "render" => {
            small_solve(args);
            small_picture(args);
            Check::Run
        }
        "verify" => {
            small_solve(args);
            set(args, "--paths", "64");
            set(args, "--grid-paths", "64");
            Check::Run
        }
        "info" | "compare" | "tonemap" => Check::Run,
        "view" => Check::NoWindow,
        // The benchmark cases are fixed (minutes in a release build).
        "bench" => Check::Parse,
        _ => return None,
    })
}

/// What a README command that is not `radiosity` must be, checked here without running it
/// (they install system packages, run the whole suite, or need Python packages).
fn other_command(command: &str) -> Result<(), String> {
    let exists = |path: &str| {
        if root().join(path).exists() { Ok(()) } else { Err(format!("{path} does not exist")) }
    };
    let words: Vec<&str> = command.split_whitespace().collect();
    match words.as_slice() {
        ["./setup.sh"] => exists("setup.sh"),
        ["cargo", "test", "--workspace"] => Ok(()),
        ["cargo", "bench", "-p", crate_name]
        | ["cargo", "bench", "-p", crate_name, "--features", "bench"] => {
            exists(&format!("crates/{crate_name}/benches"))
        }
        ["cargo", "install", "--locked", "--path", "."] => exists("Cargo.toml"),
        ["cargo", "run", "--release", "-p", crate_name, "--example", example, "--", ..] => {
            exists(&format!("crates/{crate_name}/examples/{example}.rs"))
        }
        ["pip", "install", ..] => Ok(()),
        ["python3", script, ..] => exists(script),
        _ => Err("not a command this test knows; add it to `other_command`".into()),
    }
}

/// The README's test command is one command, and CI runs exactly it: what a contributor runs
/// is what decides a merge, and nothing is built twice with other features.
#[test]
fn ci_runs_the_readme_test_command() {
    let tests: Vec<String> = readme_commands()
        .into_iter()
        .filter(|(readme, _, c)| readme == "README.md" && c.starts_with("cargo test"))
        .map(|(_, _, c)| c)
        .collect();
    assert_eq!(tests, ["cargo test --workspace"], "the README's test commands");
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    let ci_tests: Vec<&str> = ci
        .lines()
        .map(|l| l.split(" #").next().unwrap_or("").trim())
        .filter(|l| l.contains("cargo test"))
        .collect();
    assert_eq!(ci_tests, [tests[0].as_str()], ".ci/run's test commands");
}

/// Runs every README command line: `radiosity …`, `cargo run --release -- …` and
/// `scripts/xvfb-run.sh radiosity …` against the built binary, each block's commands in order
/// in a folder of its own (a later command reads what an earlier one wrote; two blocks may
/// name the same output), other commands against [`other_command`]'s list.
#[test]
fn every_readme_command_runs() {
    let mut ran = Vec::new();
    let mut dirs: Vec<(usize, tempfile::TempDir)> = Vec::new();
    for (readme, block, line) in readme_commands() {
        assert!(!line.contains(['"', '\'']), "{readme}: quoted words are not split here: {line}");
        if dirs.last().is_none_or(|(b, _)| *b != block) {
            dirs.push((block, tempfile::tempdir().unwrap()));
        }
        let dir = dirs.last().unwrap().1.path().to_owned();
        let words: Vec<&str> = line.split_whitespace().collect();
        let rest = match words.as_slice() {
            ["radiosity", rest @ ..] | ["cargo", "run", "--release", "--", rest @ ..] => rest,
            ["scripts/xvfb-run.sh", "radiosity" | "cargo", rest @ ..] => {
                assert!(root().join("scripts/xvfb-run.sh").exists());
                rest.strip_prefix(&["run", "--release", "--"][..]).unwrap_or(rest)
            }
            _ => {
                if let Err(e) = other_command(&line) {
                    panic!("{readme}: `{line}`: {e}");
                }
                continue;
            }
        };
        // Paths: scenes from the repository, /tmp into the block's folder.
        let mut args: Vec<String> = rest
            .iter()
            .map(|a| match (a.strip_prefix("scenes/"), a.strip_prefix("/tmp/")) {
                (Some(_), _) => root().join(a).display().to_string(),
                (_, Some(t)) => dir.join(t).display().to_string(),
                _ => (*a).to_owned(),
            })
            .collect();
        if args.is_empty() {
            panic!("{readme}: `{line}`: no subcommand");
        }
        let Some(check) = budget(&mut args) else {
            panic!("{readme}: `{line}`: a subcommand this test does not know how to run; add it to `budget`");
        };
        if let Check::Parse = check {
            args.push("--help".into());
        }
        let o = radiosity(&args, &dir);
        let (out, err) = text(&o);
        let shown =
            format!("{readme}: `{line}` as `radiosity {}`\nstdout:\n{out}\nstderr:\n{err}", args.join(" "));
        match check {
            Check::Run | Check::Parse => assert!(o.status.success(), "{shown}"),
            Check::NoWindow => {
                assert_eq!(o.status.code(), Some(1), "{shown}");
                let last = err.lines().last().unwrap_or_default();
                assert!(last.starts_with("error: no display to open a window on"), "{shown}");
            }
        }
        ran.push(args[0].clone());
    }
    // The READMEs show each of these; a run that saw none of one read the blocks wrongly.
    for command in ["solve", "verify", "render", "compare", "tonemap", "export", "view", "bench"] {
        assert!(ran.iter().any(|c| c == command), "no README command ran `{command}`: {ran:?}");
    }
}
