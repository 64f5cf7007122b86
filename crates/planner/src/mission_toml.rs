//! Mission segments as TOML text, for the tests, benches and examples that write their missions
//! in code: each function gives one `[[segment]]` table of a mission file, and a mission is their
//! concatenation (`[take_off(30.0, 2.0), leg(100.0, 0.0, 8.0), landing(1.0)].concat()`). Numbers
//! print in Rust's shortest round-trip form (`30.0`, `1e-320`), so the mission a test flies is the
//! one its arguments name; the keys are those of `fixtures/missions/example.toml`.

/// A vertical take-off to `altitude_m` above home at `climb_rate_mps`.
pub fn take_off(altitude_m: f64, climb_rate_mps: f64) -> String {
    format!(
        "[[segment]]\nkind = \"take-off\"\naltitude_m = {altitude_m:?}\nclimb_rate_mps = {climb_rate_mps:?}\n"
    )
}

/// A straight leg to the local point (`east_m`, `north_m`) at `ground_speed_mps`.
pub fn leg(east_m: f64, north_m: f64, ground_speed_mps: f64) -> String {
    format!(
        "[[segment]]\nkind = \"leg\"\neast_m = {east_m:?}\nnorth_m = {north_m:?}\nground_speed_mps = {ground_speed_mps:?}\n"
    )
}

/// A hover of `duration_s`.
pub fn hover(duration_s: f64) -> String {
    format!("[[segment]]\nkind = \"hover\"\nduration_s = {duration_s:?}\n")
}

/// The return over home at `ground_speed_mps`.
pub fn return_home(ground_speed_mps: f64) -> String {
    format!("[[segment]]\nkind = \"return\"\nground_speed_mps = {ground_speed_mps:?}\n")
}

/// A vertical landing at `rate_mps`.
pub fn landing(rate_mps: f64) -> String {
    format!("[[segment]]\nkind = \"landing\"\nrate_mps = {rate_mps:?}\n")
}

/// How long an orbit lasts: whole or part laps, or seconds.
pub enum OrbitFor {
    /// `laps = n`
    Laps(f64),
    /// `duration_s = t`
    Seconds(f64),
}

/// An orbit of `radius_m` about the local point `centre_en_m` (east, north) at
/// `ground_speed_mps`, `direction` "clockwise" or "counter-clockwise" seen from above.
pub fn orbit(
    centre_en_m: [f64; 2],
    radius_m: f64,
    ground_speed_mps: f64,
    direction: &str,
    lasting: OrbitFor,
) -> String {
    let [east, north] = centre_en_m;
    let until = match lasting {
        OrbitFor::Laps(laps) => format!("laps = {laps:?}"),
        OrbitFor::Seconds(s) => format!("duration_s = {s:?}"),
    };
    format!(
        "[[segment]]\nkind = \"orbit\"\ncentre_east_m = {east:?}\ncentre_north_m = {north:?}\n\
         radius_m = {radius_m:?}\nground_speed_mps = {ground_speed_mps:?}\n\
         direction = \"{direction}\"\n{until}\n"
    )
}

/// `segment` (a leg or an orbit) flown at `altitude_m` above home instead of the height it starts
/// at.
pub fn at_altitude(segment: String, altitude_m: f64) -> String {
    format!("{segment}altitude_m = {altitude_m:?}\n")
}
