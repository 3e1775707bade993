//! Contact laws between grains, and between a grain and a wall.
