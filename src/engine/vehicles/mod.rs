//! Vehicles: the built-in and file vehicles every command flies, the one take-off mass, calibration
//! from a spec sheet or a published hover time, and a vehicle made from a flight log's own figures.

pub(crate) mod calibrate;
pub(crate) mod vehicle;
