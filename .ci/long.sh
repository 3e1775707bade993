#!/usr/bin/env bash
# The long tier of the test suite: the tests marked
# `cfg_attr(not(feature = "long-tests"), ignore = ...)`, which the README's
# `cargo test --profile opt-test` lists as ignored: the convection seed
# ensembles (tests/seeds) and the silo discharge through an STL floor
# (tests/scenarios/mesh_discharge.rs), minutes each. CI runs it after the
# default suite; by hand:
#
#   .ci/long.sh
set -euxo pipefail

cd "$(dirname "$0")/.."

cargo test --profile opt-test -p grains --features long-tests --test seeds --test scenarios
