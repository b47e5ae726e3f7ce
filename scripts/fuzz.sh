#!/usr/bin/env bash
# Runs every fuzz target in fuzz/ (scene TOML, OBJ + MTL, glTF/GLB, PFM, EXR, IES / EULUMDAT) for a bounded
# time each, with libFuzzer through `cargo fuzz` on nightly Rust. Not part of CI's default
# run: it needs a nightly toolchain and cargo-fuzz, and minutes per target.
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]    # default 60 s, every target
#
# A crash stops its target and leaves the input in fuzz/artifacts/TARGET/; replay it with
# `cargo +nightly fuzz run TARGET fuzz/artifacts/TARGET/crash-…`, fix it, and add a test in
# tests/suite/bad_input.rs (or the crate's tests) that fails before the fix. The corpus
# grows in fuzz/corpus/ (not committed); fuzz/seeds/ holds the few small starting inputs
# that are.
set -euo pipefail

seconds="${1:-60}"
shift || true
if ! [[ "$seconds" =~ ^[0-9]+$ ]] || [ "$seconds" -eq 0 ]; then
    echo "usage: $0 [SECONDS_PER_TARGET] [TARGET...]   (SECONDS a whole number > 0)" >&2
    exit 2
fi
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(scene_toml obj_mtl gltf pfm exr photometric)
fi

if ! rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
    echo "fuzzing needs a nightly Rust toolchain: rustup toolchain install nightly" >&2
    exit 1
fi
if ! cargo +nightly fuzz --version >/dev/null 2>&1; then
    echo "fuzzing needs cargo-fuzz: cargo install cargo-fuzz" >&2
    exit 1
fi

root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
failed=()
for t in "${targets[@]}"; do
    mkdir -p "fuzz/corpus/$t"
    echo "== $t: ${seconds} s"
    # -malloc_limit_mb: an input that makes a run allocate past 2 GB at once is a finding (the
    # bad-input aborts were allocations of gigabytes); -rss_limit_mb is set apart from it and
    # higher, since the sanitiser's own memory creeps up over an hour of runs (an OpenEXR run
    # stopped at 2 GB of RSS with 29 MB live, its last input replaying at 7 MB); -timeout:
    # one input running 30 s is a hang. The
    # targets run under AddressSanitizer, about ten times slower than a release build: a
    # Cornell box with one wall stretched meshes in 1.1 s released and took 13 s here.
    if ! cargo +nightly fuzz run "$t" "fuzz/corpus/$t" "fuzz/seeds/$t" -- \
        -max_total_time="$seconds" -malloc_limit_mb=2048 -rss_limit_mb=4096 -timeout=30 -max_len=1048576; then
        failed+=("$t")
    fi
done
if [ ${#failed[@]} -gt 0 ]; then
    echo "findings in: ${failed[*]} (inputs in fuzz/artifacts/)" >&2
    exit 1
fi
echo "no findings in ${#targets[@]} target(s), ${seconds} s each"
