#!/usr/bin/env bash
# CI for the one run loop (#27): the house rules (tools/check_layers.py: no
# source file over 800 lines, runner/ under 2,500, imports only downward in
# the layers of ARCHITECTURE.md, no two files importing each other); then
# every shipped scenario and the default run
# write the files of 51f08da (the commit before the redesign) byte for byte,
# 300 steps on 1, 2 and 4 threads. The reference build is cached by
# tools/same_bits.sh (SAME_BITS_CACHE), so a second run only rebuilds this
# tree. Needs python3 and the full git history.
set -euxo pipefail
cd "$(dirname "$0")/.."
command -v python3
python3 tools/check_layers.py
ref=51f08da677c53a5e2a04e92045442aba1f403cc1
git cat-file -e "$ref^{commit}"
THREADS="1 2 4" tools/same_bits.sh "$ref"
