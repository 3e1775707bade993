//! Pictures and movies of runs: frames drawn with their walls at each
//! instant and a band with the time, a scale bar and the colour legend.
//!
//! `scene` is what a run directory carries to draw it later (box, walls),
//! `wires` turns walls into drawable lines at a time, `still` paints one
//! frame, `legend` and `text` draw the band, `movie` encodes a series.

pub mod legend;
pub mod movie;
pub mod scene;
pub mod still;
pub mod text;
pub mod wires;

pub use movie::{make_movie, MovieOptions, MovieReport};
pub use scene::Scene;
pub use still::{ColorBy, Painter, Projection, StillOptions, ViewAxis};
pub use wires::{wires_at, Wire};
