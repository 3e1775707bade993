//! Walls and obstacles: geometry, prescribed motions, contacts with grains.
