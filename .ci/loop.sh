#!/usr/bin/env bash
# CI for the one run loop (#27): the house rules (tools/check_layers.py: no
# source file over 800 lines, runner/ under 2,500, imports only downward in
# the layers of ARCHITECTURE.md, no two files importing each other); then
# every shipped scenario and the default run write the files of a reference
# commit byte for byte, 300 steps on 1, 2 and 4 threads: `.ci/loop.sh REF`
# (default HEAD, the previous main for a change not yet committed). The reference build is cached by
# tools/same_bits.sh (SAME_BITS_CACHE), so a second run only rebuilds this
# tree. Needs python3 and the full git history.
set -euxo pipefail
cd "$(dirname "$0")/.."
command -v python3
python3 tools/check_layers.py
ref=${1:-HEAD}
git cat-file -e "$ref^{commit}"
THREADS="1 2 4" tools/same_bits.sh "$ref"
