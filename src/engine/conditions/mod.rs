//! The day's conditions: the air (density from altitude, temperature, pressure and humidity, or
//! given), the wind (a forecast, a profile with height, a gridded field, gusts) and the ground
//! under the route (elevation tiles, `terrain`).

pub(crate) mod air;
pub mod terrain;
pub(crate) mod wind;
