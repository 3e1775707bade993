//! Time integrators: fifth-order Gear predictor–corrector and velocity Verlet.
