//! The page's maps (`aloft serve`): a mission's route, its samples and its state-of-charge fan
//! as map layers, the route's profile over the ground (with terrain), and a plan to fly's sorties
//! on the same map.

pub(crate) mod mission_map;
pub(crate) mod plan_map;
pub(crate) mod profile;
