//! Plans to fly (`aloft plan`): speeds chosen for the wind, surveys turned to it, sorties cut
//! inside legs where each pack reaches the reserve, the files written per battery and read back,
//! and the page's map of them.

pub(crate) mod fly_plan;
pub(crate) mod follow;
pub(crate) mod plan_files;
pub(crate) mod survey_angle;
