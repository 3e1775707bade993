#!/usr/bin/env bash
# Runs every shipped scenario (and the built-in default) for a few hundred
# steps with the working tree's build and with a reference commit's build,
# on 1 and 2 threads, and compares every file the runs write byte for byte
# (summary.json without its timings). Run it before each commit that should
# not change results; a commit that changes them on purpose says so.
#
#   tools/same_bits.sh              # against HEAD (the previous main)
#   tools/same_bits.sh abc1234      # against another commit
#   STEPS=500 THREADS="1 2 4" tools/same_bits.sh
#
# The reference is built once per commit in a worktree under
# ${SAME_BITS_CACHE:-/tmp/grains-same-bits} (its own target directory), with
# the same cargo profile (PROFILE, default opt-test: the release arithmetic
# without LTO's long link). Needs python3. Exit status 1 when a file differs.
set -euo pipefail
ref=${1:-HEAD}
steps=${STEPS:-300}
threads=${THREADS:-"1 2"}
profile=${PROFILE:-opt-test}
root=$(cd "$(dirname "$0")/.." && pwd)
cache=${SAME_BITS_CACHE:-/tmp/grains-same-bits}
sha=$(git -C "$root" rev-parse --verify "$ref^{commit}")
refdir="$cache/$sha"

if [ ! -d "$refdir" ]; then
  mkdir -p "$cache"
  git -C "$root" worktree add --detach "$refdir" "$sha" >/dev/null
  # Start from this tree's compiled dependencies, when there are any.
  src_target="${CARGO_TARGET_DIR:-$root/target}"
  [ -d "$src_target/$profile" ] && mkdir -p "$refdir/target" \
    && cp -a "$src_target/$profile" "$refdir/target/"
fi
echo "building the reference $sha ($profile)" >&2
(cd "$refdir" && CARGO_TARGET_DIR="$refdir/target" cargo build -q --profile "$profile" -p grains-cli)
echo "building the working tree ($profile)" >&2
(cd "$root" && cargo build -q --profile "$profile" -p grains-cli)
bin_ref="$refdir/target/$profile/grains"
bin_new="${CARGO_TARGET_DIR:-$root/target}/$profile/grains"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Scenarios whose inputs are relative paths are run from the scenario folder.
scenarios=("" "$root"/scenarios/*.toml)
for t in $threads; do
  for s in "${scenarios[@]}"; do
    name=${s:+$(basename "$s" .toml)}
    name=${name:-default}
    for side in ref new; do
      bin=$bin_ref
      [ "$side" = new ] && bin=$bin_new
      out="$work/$side/t$t/$name"
      # A run that fails must fail the same way on both sides.
      if ! "$bin" run ${s:+"$s"} --steps "$steps" --threads "$t" --out "$out" --quiet \
        >"$work/$side-$t-$name.log" 2>&1; then
        echo "exit $?" >>"$work/$side-$t-$name.log"
      fi
      mkdir -p "$out"
      mv "$work/$side-$t-$name.log" "$out/run.log"
    done
  done
done

python3 - "$work/ref" "$work/new" <<'PY'
import json, os, sys
ref, new = sys.argv[1], sys.argv[2]
TIMINGS = {"ns_per_particle_step", "threads"}

def drop_timings(x):
    """Removes wall-clock keys (every `*_seconds` and the rates) at any depth."""
    if isinstance(x, dict):
        return {k: drop_timings(v) for k, v in x.items()
                if k not in TIMINGS and not k.endswith("_seconds")}
    if isinstance(x, list):
        return [drop_timings(v) for v in x]
    return x

def files(top):
    out = set()
    for d, _, names in os.walk(top):
        for n in names:
            out.add(os.path.relpath(os.path.join(d, n), top))
    return out

def content(path):
    with open(path, "rb") as f:
        data = f.read()
    if os.path.basename(path) == "summary.json":
        return json.dumps(drop_timings(json.loads(data)), sort_keys=True).encode()
    return data

a, b = files(ref), files(new)
bad = sorted(a ^ b)
for f in bad:
    print(f"only on one side: {f}")
same = 0
for f in sorted(a & b):
    if content(os.path.join(ref, f)) == content(os.path.join(new, f)):
        same += 1
    else:
        print(f"differs: {f}")
        bad.append(f)
print(f"{same} files identical, {len(bad)} differ")
sys.exit(1 if bad else 0)
PY
