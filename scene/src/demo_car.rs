//! The procedural demo car.
