//! The day's conditions: the air (density from altitude, temperature, pressure and humidity, or
//! given) and the wind (a forecast, a profile with height, a gridded field, gusts).

pub(crate) mod air;
pub(crate) mod wind;
