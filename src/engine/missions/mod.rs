//! Missions: a mission read from any planner file, the options it flies with and the day it
//! flies in (its air and wind), its flight segment by segment, its sorties when one pack cannot
//! fly it all, the summary (energy, the reserve, the point of no return, failsafes), loiters, and
//! the files it writes (time series, MCAP, plots).

pub(crate) mod day;
pub(crate) mod flight;
pub(crate) mod flown;
pub(crate) mod ground;
pub(crate) mod loiter;
pub(crate) mod mission;
pub(crate) mod mission_file;
pub(crate) mod mission_options;
pub(crate) mod mission_outputs;
pub(crate) mod sorties;
pub(crate) mod summary;
