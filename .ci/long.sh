#!/usr/bin/env bash
# The long tier of the test suite: the tests marked
# `cfg_attr(not(feature = "long-tests"), ignore = ...)`, which the README's
# `cargo test --profile opt-test` lists as ignored: the convection seed
# ensembles and the conveyor's saturation (tests/seeds), the silo discharge
# through an STL floor, the 3D sand pile over rolling friction, the
# repose ensemble of spheres, dimers and tetrahedral clumps and the
# chute's stress and velocity profiles (tests/scenarios), from 40 s to
# minutes each. CI runs it after the
# default suite; by hand:
#
#   .ci/long.sh
set -euxo pipefail

cd "$(dirname "$0")/.."

cargo test --profile opt-test -p grains --features long-tests --test seeds --test scenarios
