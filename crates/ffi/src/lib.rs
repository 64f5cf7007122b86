//! # aloft-ffi: the C ABI of aloft
//!
//! A ground station (C, C++, C#, Python through `ctypes`/`cffi`) loads vehicles, evaluates the
//! power model, plans missions and runs the endurance queries through this ABI. It is a thin layer
//! over [`aloft::engine`]: results are the same JSON text as the CLI's `--format json`.
//! The header `include/aloft.h` is generated from this file by cbindgen and committed.
//!
//! ## Conventions
//! - Every function that can fail returns an [`AloftStatus`] (`ALOFT_STATUS_OK` is 0) and writes its
//!   result through an out pointer, which is set to NULL (or left untouched for numbers) on failure.
//! - After a failure, [`aloft_last_error_message`] gives a message for the calling thread. Each
//!   fallible call clears it first, so after a success it is the empty string.
//! - Text in and out is NUL-terminated UTF-8. Invalid UTF-8 is `ALOFT_STATUS_INVALID_UTF8`, a NULL
//!   where a value is needed `ALOFT_STATUS_NULL_POINTER`.
//! - No panic crosses the boundary: a panic inside is caught and returned as
//!   `ALOFT_STATUS_PANIC` (build with the default `panic = "unwind"`).
//! - Thread safety: vehicles and plans are immutable after creation; any number of threads may
//!   use the same handle at once. Freeing a handle while another thread uses it is the caller's
//!   error.
//!
//! ## Ownership
//! - `aloft_vehicle_*` constructors return an `AloftVehicle *` that the caller owns and releases
//!   with [`aloft_vehicle_free`]; `aloft_mission_plan` returns an `AloftPlan *` released with
//!   [`aloft_plan_free`]. A plan does not borrow its vehicle: either may be freed first.
//! - Functions that return `char *` through an out pointer hand over a string the caller owns and
//!   releases with [`aloft_string_free`] (never with `free`).
//! - `const char *` returned directly ([`aloft_version`], [`aloft_demo_mission_toml`],
//!   [`aloft_last_error_message`]) are owned by the library: never free them. The last-error text
//!   is valid until the next aloft call on the same thread; the others for the program's life.
//! - The library keeps a registry of the handles and strings it has handed out, and every handle
//!   carries a magic number. A pointer that is not live (freed already, never returned by aloft, or
//!   a handle of another kind) is refused with `ALOFT_STATUS_BAD_HANDLE` without being
//!   dereferenced, so freeing twice is an error code, not a crash. Freeing NULL is a no-op that
//!   returns `ALOFT_STATUS_OK`, as `free(NULL)`. The guard cannot tell a stale pointer from a new
//!   object that happens to be allocated at the same address: set pointers to NULL after freeing.
//!
//! ## Mission text
//! Missions are the mission file format as TOML, or the same structure as JSON (a text whose first
//! non-blank character is `{`), or NULL for the built-in demonstration mission. Options are a JSON
//! object with the keys of [`aloft::engine::MissionOptions`] or
//! [`aloft::engine::EnduranceOptions`] (all optional; NULL or `{}` for the CLI's defaults).

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

use std::collections::BTreeMap;
use std::ffi::{c_char, c_int, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{LazyLock, Mutex, MutexGuard};

use aloft::engine::{
    endurance, options_from_json, plan_mission, plan_scenarios, power_point, EnduranceOptions,
    FlightState, FlightStateDeg, Mission, MissionOptions, MissionWithUncertainty, Plan,
    PowerModelQuery, PowerQuery, Vehicle,
};
use aloft::Error;

/// Result of every fallible call. `ALOFT_STATUS_OK` (0) is success; see
/// `aloft_last_error_message()` for the reason of any other value.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AloftStatus {
    /// Success.
    Ok = 0,
    /// A required pointer argument (input text, handle or out pointer) was NULL.
    NullPointer = 1,
    /// Input text is not valid UTF-8.
    InvalidUtf8 = 2,
    /// Text that does not parse: a vehicle or mission (TOML/JSON) or an options document (JSON).
    Parse = 3,
    /// A value outside its valid range, or a vehicle without the table the call needs.
    InvalidInput = 4,
    /// A name that is not known (built-in vehicle, battery pack), or a vehicle file that does
    /// not exist.
    NotFound = 5,
    /// The mission cannot be flown by this vehicle (segment beyond its limits, too heavy, out of
    /// order). An infeasible mission (reserve not held) is NOT an error: see `feasible`.
    Mission = 6,
    /// A handle or string that is not live: already freed, not from aloft, or of another kind.
    BadHandle = 7,
    /// An internal error (a caught panic). Please report it.
    Panic = 8,
}

const VEHICLE_MAGIC: u64 = 0x616c_6f66_7456_4548; // "aloftVEH"
const PLAN_MAGIC: u64 = 0x616c_6f66_7450_4c4e; // "aloftPLN"

/// A loaded vehicle (opaque). Create with `aloft_vehicle_builtin` or `aloft_vehicle_from_toml`,
/// release with `aloft_vehicle_free`.
pub struct AloftVehicle {
    magic: u64,
    inner: Vehicle,
}

/// A planned mission (opaque). Create with `aloft_mission_plan`, release with `aloft_plan_free`.
pub struct AloftPlan {
    magic: u64,
    inner: Plan,
}

/// What the registry-checked handle functions need to know of a handle type.
trait Handle: Sized {
    /// The Rust value behind the handle.
    type Inner;
    /// Registry kind.
    const KIND: Kind;
    /// Magic number of a live handle.
    const MAGIC: u64;
    fn wrap(inner: Self::Inner) -> Self;
    fn magic(&self) -> u64;
    fn clear_magic(&mut self);
    fn inner(&self) -> &Self::Inner;
}

macro_rules! handle {
    ($t:ty, $inner:ty, $kind:expr, $magic:expr) => {
        impl Handle for $t {
            type Inner = $inner;
            const KIND: Kind = $kind;
            const MAGIC: u64 = $magic;
            fn wrap(inner: $inner) -> Self {
                Self {
                    magic: $magic,
                    inner,
                }
            }
            fn magic(&self) -> u64 {
                self.magic
            }
            fn clear_magic(&mut self) {
                self.magic = 0;
            }
            fn inner(&self) -> &$inner {
                &self.inner
            }
        }
    };
}

handle!(AloftVehicle, Vehicle, Kind::Vehicle, VEHICLE_MAGIC);
handle!(AloftPlan, Plan, Kind::Plan, PLAN_MAGIC);

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Vehicle,
    Plan,
    String,
}

/// Addresses of live handles and strings: the double-free and wrong-pointer guard. Keys are the
/// addresses XOR [`KEY_MASK`], so the registry holds no pointer: a leak checker (valgrind, ASan)
/// still reports a handle the caller forgot to free as lost, not as reachable.
static LIVE: Mutex<BTreeMap<usize, Kind>> = Mutex::new(BTreeMap::new());

/// Mask of the registry keys (no valid address pattern survives it).
const KEY_MASK: usize = usize::MAX ^ 0x5a5a;

fn key<T>(ptr: *const T) -> usize {
    ptr as usize ^ KEY_MASK
}

fn live() -> MutexGuard<'static, BTreeMap<usize, Kind>> {
    // A panic while holding the lock cannot leave the map inconsistent (single inserts/removes).
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

thread_local! {
    static LAST_ERROR: std::cell::RefCell<CString> = std::cell::RefCell::new(CString::default());
}

fn set_last_error(message: &str) {
    let c = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| {
        if let Ok(mut slot) = e.try_borrow_mut() {
            *slot = c;
        }
    });
}

/// A failed call: its status and message.
struct Failure {
    status: AloftStatus,
    message: String,
}

impl Failure {
    fn new(status: AloftStatus, message: impl Into<String>) -> Self {
        Self {
            status,
            message: message.into(),
        }
    }
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        let status = match &e {
            Error::UnknownVehicle { .. } | Error::NoSuchVehicleFile { .. } => AloftStatus::NotFound,
            Error::VehicleFormat { message, .. } if message.starts_with("no battery") => {
                AloftStatus::NotFound
            }
            Error::VehicleFormat { .. }
            | Error::MissionFormat { .. }
            | Error::MissionImport { .. }
            | Error::OptionsFormat { .. } => AloftStatus::Parse,
            Error::Mission { .. } | Error::TooHeavy { .. } => AloftStatus::Mission,
            _ => AloftStatus::InvalidInput,
        };
        Failure::new(status, e.to_string())
    }
}

/// Run `f` with panics caught; record the message of a failure for this thread.
fn guard(f: impl FnOnce() -> Result<(), Failure>) -> AloftStatus {
    set_last_error("");
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => AloftStatus::Ok,
        Ok(Err(fail)) => {
            set_last_error(&fail.message);
            fail.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_string());
            set_last_error(&format!(
                "internal error (panic caught at the C boundary): {what}"
            ));
            AloftStatus::Panic
        }
    }
}

/// Borrow a C string as UTF-8 text; `name` is the argument's name for the message.
///
/// # Safety
/// `p` is NULL or points to a NUL-terminated string that outlives the call.
unsafe fn text<'a>(p: *const c_char, name: &str) -> Result<&'a str, Failure> {
    if p.is_null() {
        return Err(Failure::new(
            AloftStatus::NullPointer,
            format!("{name} is NULL"),
        ));
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    let c = unsafe { CStr::from_ptr(p) };
    c.to_str().map_err(|e| {
        Failure::new(
            AloftStatus::InvalidUtf8,
            format!(
                "{name} is not valid UTF-8 (first invalid byte at offset {})",
                e.valid_up_to()
            ),
        )
    })
}

/// Like [`text`] but NULL is `None`.
unsafe fn optional_text<'a>(p: *const c_char, name: &str) -> Result<Option<&'a str>, Failure> {
    if p.is_null() {
        Ok(None)
    } else {
        // SAFETY: forwarded contract.
        unsafe { text(p, name) }.map(Some)
    }
}

/// Check an out pointer and clear what it points to.
unsafe fn out_ptr<'a, T>(p: *mut *mut T, name: &str) -> Result<&'a mut *mut T, Failure> {
    if p.is_null() {
        return Err(Failure::new(
            AloftStatus::NullPointer,
            format!("{name} (out pointer) is NULL"),
        ));
    }
    // SAFETY: non-null, and the caller passes a valid, writable pointer.
    let slot = unsafe { &mut *p };
    *slot = std::ptr::null_mut();
    Ok(slot)
}

fn register<T>(ptr: *mut T, kind: Kind) -> *mut T {
    live().insert(key(ptr), kind);
    ptr
}

fn not_live(name: &str, kind: Kind) -> Failure {
    Failure::new(
        AloftStatus::BadHandle,
        format!(
            "{name} is not a live aloft {}: freed already, not returned by aloft, or another kind of object",
            match kind {
                Kind::Vehicle => "vehicle",
                Kind::Plan => "plan",
                Kind::String => "string",
            }
        ),
    )
}

/// Hand a string to the caller (registered, to be released with `aloft_string_free`).
fn give_string(s: String, out: &mut *mut c_char) -> Result<(), Failure> {
    let c = CString::new(s).map_err(|_| {
        Failure::new(
            AloftStatus::Panic,
            "internal error: a result holds a NUL byte",
        )
    })?;
    *out = register(c.into_raw(), Kind::String);
    Ok(())
}

/// Borrow the value behind a live handle.
///
/// # Safety
/// `h` is NULL or a pointer the caller got from aloft (checked against the registry before use).
unsafe fn borrow<'a, H: Handle + 'a>(h: *const H, name: &str) -> Result<&'a H::Inner, Failure> {
    if h.is_null() {
        return Err(Failure::new(
            AloftStatus::NullPointer,
            format!("{name} is NULL"),
        ));
    }
    if live().get(&key(h)) != Some(&H::KIND) {
        return Err(not_live(name, H::KIND));
    }
    // SAFETY: registered as a live handle of this kind, so it points to an `H` we allocated.
    let handle = unsafe { &*h };
    if handle.magic() != H::MAGIC {
        return Err(not_live(name, H::KIND));
    }
    Ok(handle.inner())
}

/// Borrow a live vehicle.
///
/// # Safety
/// As [`borrow`].
unsafe fn vehicle<'a>(v: *const AloftVehicle, name: &str) -> Result<&'a Vehicle, Failure> {
    unsafe { borrow(v, name) }
}

/// Borrow a live plan.
///
/// # Safety
/// As [`borrow`].
unsafe fn plan<'a>(p: *const AloftPlan, name: &str) -> Result<&'a Plan, Failure> {
    unsafe { borrow(p, name) }
}

/// Remove `ptr` from the registry if it is a live `kind`; true when it was.
fn unregister<T>(ptr: *const T, kind: Kind) -> bool {
    let mut map = live();
    let k = key(ptr);
    if map.get(&k) == Some(&kind) {
        map.remove(&k);
        true
    } else {
        false
    }
}

/// Box `inner` as a registered handle into `*out`.
fn give<H: Handle>(inner: H::Inner, out: &mut *mut H) {
    *out = register(Box::into_raw(Box::new(H::wrap(inner))), H::KIND);
}

/// Release a handle: NULL is a no-op; a pointer that is not a live handle of this kind is an
/// error and is not touched.
///
/// # Safety
/// `h` is NULL or a pointer; it is checked against the registry before use.
unsafe fn release<H: Handle>(h: *mut H, name: &str) -> Result<(), Failure> {
    if h.is_null() {
        return Ok(());
    }
    if !unregister(h, H::KIND) {
        return Err(not_live(name, H::KIND));
    }
    // SAFETY: it was live and is now out of the registry: we own it, exactly once.
    let mut b = unsafe { Box::from_raw(h) };
    b.clear_magic();
    drop(b);
    Ok(())
}

/// A non-NULL scalar out-parameter, or `NullPointer` naming it.
///
/// # Safety
/// `p` is NULL or a valid, writable pointer.
unsafe fn out_value<'a, T>(p: *mut T, name: &str) -> Result<&'a mut T, Failure> {
    if p.is_null() {
        return Err(Failure::new(
            AloftStatus::NullPointer,
            format!("{name} (out pointer) is NULL"),
        ));
    }
    // SAFETY: non-null, writable by the caller's contract.
    Ok(unsafe { &mut *p })
}

fn parse_mission(mission: Option<&str>) -> Result<Mission, Failure> {
    Ok(match mission {
        None => Mission::demo(),
        Some(t) => Mission::from_text(t, "from the C caller")?,
    })
}

fn parse_mission_options(options: Option<&str>) -> Result<MissionOptions, Failure> {
    Ok(match options {
        None => MissionOptions::default(),
        Some(t) => MissionOptions::from_json(t)?,
    })
}

/// The mission argument: TOML or JSON text, or NULL for the demonstration mission.
///
/// # Safety
/// `mission` is NULL or a NUL-terminated string that outlives the call.
unsafe fn mission_arg(mission: *const c_char) -> Result<Mission, Failure> {
    // SAFETY: forwarded contract.
    parse_mission(unsafe { optional_text(mission, "mission")? })
}

/// The shape of every entry point that answers about a handle: panics caught, the out pointer
/// `out` (named `out_name`) checked and cleared, then the handle `h` (named `name`) checked
/// against the registry, then `answer` with the value behind the handle and the out pointer.
///
/// # Safety
/// `h` is NULL or a pointer (checked); `out` is NULL or a writable pointer.
unsafe fn with_handle<H: Handle, T>(
    (h, name): (*const H, &str),
    (out, out_name): (*mut *mut T, &str),
    answer: impl FnOnce(&H::Inner, &mut *mut T) -> Result<(), Failure>,
) -> AloftStatus {
    guard(|| {
        // SAFETY: the caller's contract; the handle is checked against the registry.
        let out = unsafe { out_ptr(out, out_name)? };
        let inner = unsafe { borrow(h, name)? };
        answer(inner, out)
    })
}

/// The shape of the constructors of a vehicle from one text argument `arg` (named `name`):
/// panics caught, `out` checked and cleared, then the text, then the vehicle `make` builds.
///
/// # Safety
/// `arg` is NULL or a NUL-terminated string; `out` is NULL or a writable pointer.
unsafe fn new_vehicle(
    arg: *const c_char,
    name: &str,
    out: *mut *mut AloftVehicle,
    make: impl FnOnce(&str) -> Result<Vehicle, Error>,
) -> AloftStatus {
    guard(|| {
        // SAFETY: the caller's contract.
        let out = unsafe { out_ptr(out, "out")? };
        let arg = unsafe { text(arg, name)? };
        give(make(arg)?, out);
        Ok(())
    })
}

static VERSION: LazyLock<CString> =
    LazyLock::new(|| CString::new(env!("CARGO_PKG_VERSION")).unwrap_or_default());

static DEMO_MISSION: LazyLock<CString> =
    LazyLock::new(|| CString::new(aloft::engine::DEMO_MISSION).unwrap_or_default());

/// The library's version, e.g. `"0.1.0"`. Owned by the library: do not free.
#[no_mangle]
pub extern "C" fn aloft_version() -> *const c_char {
    catch_unwind(|| VERSION.as_ptr()).unwrap_or(std::ptr::null())
}

/// The built-in demonstration mission as TOML text (what a NULL mission means). Owned by the
/// library: do not free.
#[no_mangle]
pub extern "C" fn aloft_demo_mission_toml() -> *const c_char {
    catch_unwind(|| DEMO_MISSION.as_ptr()).unwrap_or(std::ptr::null())
}

/// The message of the last failed aloft call on this thread, or `""` when the last call
/// succeeded. Owned by the library, valid until the next aloft call on this thread: copy it to
/// keep it. Never NULL.
#[no_mangle]
pub extern "C" fn aloft_last_error_message() -> *const c_char {
    static EMPTY: &CStr = c"";
    catch_unwind(|| {
        LAST_ERROR.with(|e| match e.try_borrow() {
            // The CString's buffer stays put until the next call replaces it.
            Ok(s) => s.as_ptr(),
            Err(_) => EMPTY.as_ptr(),
        })
    })
    .unwrap_or(EMPTY.as_ptr())
}

/// Load a built-in vehicle by name (e.g. `"dji-m100"`) into `*out`.
///
/// # Safety
/// `name` is NULL or a NUL-terminated string; `out` is NULL or a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn aloft_vehicle_builtin(
    name: *const c_char,
    out: *mut *mut AloftVehicle,
) -> AloftStatus {
    // SAFETY: the caller's contract.
    unsafe { new_vehicle(name, "name", out, Vehicle::builtin) }
}

/// Load a vehicle from the text of a vehicle file (TOML) into `*out`.
///
/// # Safety
/// `toml` is NULL or a NUL-terminated string; `out` is NULL or a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn aloft_vehicle_from_toml(
    toml: *const c_char,
    out: *mut *mut AloftVehicle,
) -> AloftStatus {
    // SAFETY: the caller's contract.
    unsafe {
        new_vehicle(toml, "toml", out, |t| {
            Vehicle::from_toml(t, "vehicle text from the C caller")
        })
    }
}

/// Release a vehicle. NULL is a no-op; a pointer that is not a live vehicle (e.g. freed already)
/// returns `ALOFT_STATUS_BAD_HANDLE` and is not touched.
///
/// # Safety
/// `vehicle` is NULL or a pointer; it is checked against the registry before use.
#[no_mangle]
pub unsafe extern "C" fn aloft_vehicle_free(vehicle: *mut AloftVehicle) -> AloftStatus {
    // SAFETY: checked against the registry before use.
    guard(|| unsafe { release(vehicle, "vehicle") })
}

/// Electrical power of the four-term model in steady flight, W, into `*out_w`: airspeed in m/s,
/// roll and pitch in radians (the paper's angle of attack from them), climb rate in m/s (positive
/// up). The vehicle flies its default take-off mass, airframe + default pack (no payload), as
/// `aloft power` does without `--battery` and `--payload-kg`; `aloft_vehicle_power_json` takes
/// both.
///
/// # Safety
/// `vehicle` is NULL or a pointer (checked); `out_w` is NULL or a writable `double`.
#[no_mangle]
pub unsafe extern "C" fn aloft_vehicle_power_w(
    vehicle: *const AloftVehicle,
    airspeed_mps: f64,
    roll_rad: f64,
    pitch_rad: f64,
    climb_rate_mps: f64,
    out_w: *mut f64,
) -> AloftStatus {
    guard(|| {
        // SAFETY: checked against the registry.
        let v = unsafe { self::vehicle(vehicle, "vehicle")? };
        let out_w = unsafe { out_value(out_w, "out_w")? };
        let p = v.power(&FlightState::new(
            airspeed_mps,
            roll_rad,
            pitch_rad,
            climb_rate_mps,
        ))?;
        *out_w = p.electrical_w;
        Ok(())
    })
}

/// Every term of the four-term model as JSON (the keys of `aloft power --format json`:
/// `takeoff_mass_kg`, `battery`, `payload_kg`, `thrust_n`, `induced_w`, ..., `electrical_w`) for
/// a flight state given as JSON:
/// `{"airspeed_mps": 5, "roll_deg": 0, "pitch_deg": -5, "climb_rate_mps": 0}` (missing keys are
/// 0), with optionally the take-off mass's `"battery": "TB48D"` (default: the vehicle's default
/// pack) and `"payload_kg": 0.5` (default 0), as `aloft power --battery --payload-kg`.
/// The string written to `*out_json` is released with `aloft_string_free`.
///
/// # Safety
/// `vehicle` is NULL or a pointer (checked); `state_json` is NULL or a NUL-terminated string;
/// `out_json` is NULL or a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn aloft_vehicle_power_json(
    vehicle: *const AloftVehicle,
    state_json: *const c_char,
    out_json: *mut *mut c_char,
) -> AloftStatus {
    #[derive(serde::Deserialize, Default)]
    #[serde(deny_unknown_fields, default)]
    struct StateJson {
        airspeed_mps: f64,
        roll_deg: f64,
        pitch_deg: f64,
        climb_rate_mps: f64,
        battery: Option<String>,
        payload_kg: f64,
    }
    // SAFETY: the caller's contract; the handle is checked against the registry.
    unsafe {
        with_handle((vehicle, "vehicle"), (out_json, "out_json"), |v, out| {
            let state = text(state_json, "state_json")?;
            let s: StateJson = serde_json::from_str(state).map_err(|e| {
                Failure::new(AloftStatus::Parse, format!("invalid flight state: {e}"))
            })?;
            let query = PowerQuery {
                model: PowerModelQuery {
                    battery: s.battery,
                    payload_kg: s.payload_kg,
                    ..PowerModelQuery::default()
                },
                state: FlightStateDeg {
                    airspeed_mps: s.airspeed_mps,
                    roll_deg: s.roll_deg,
                    pitch_deg: s.pitch_deg,
                    climb_rate_mps: s.climb_rate_mps,
                    air_direction_deg: None,
                },
                gradient: false,
            };
            let json = serde_json::to_string_pretty(&power_point(v, &query)?)
                .map_err(|e| Failure::new(AloftStatus::InvalidInput, e.to_string()))?;
            give_string(json, out)
        })
    }
}

/// Plan a mission with `vehicle` into `*out`. `mission` is TOML or JSON text, or NULL for the
/// built-in demonstration mission; `options_json` is NULL (the CLI's defaults) or a JSON object
/// of mission options (`battery`, `payload_kg`, `wind`, `reserve_percent`, `start_percent` or
/// `start_voltage_v`, `time_step_s`, `aoa`, `ground_effect`). An infeasible mission is a plan
/// with `feasible` false.
///
/// # Safety
/// `vehicle` is NULL or a pointer (checked); `mission` and `options_json` are NULL or
/// NUL-terminated strings; `out` is NULL or a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn aloft_mission_plan(
    vehicle: *const AloftVehicle,
    mission: *const c_char,
    options_json: *const c_char,
    out: *mut *mut AloftPlan,
) -> AloftStatus {
    // SAFETY: the caller's contract; the handle is checked against the registry.
    unsafe {
        with_handle((vehicle, "vehicle"), (out, "out"), |v, out| {
            let mission = mission_arg(mission)?;
            let options = parse_mission_options(optional_text(options_json, "options_json")?)?;
            give(plan_mission(v, &mission, &options)?, out);
            Ok(())
        })
    }
}

/// One call from text to text: plan `mission` (TOML, JSON or NULL for the demo) with `vehicle`
/// and write the summary JSON (exactly `aloft mission --format json` without its final newline)
/// to `*out_json`, released with `aloft_string_free`.
///
/// The options JSON may hold a `scenarios` object (`{"scenarios": {"samples": 1000,
/// "payload_sd_kg": 0.1}}`, keys of `aloft::engine::ScenarioOptions`): the JSON then carries
/// the `uncertainty` of that many Monte-Carlo scenarios, exactly as `aloft mission --samples N
/// --format json`.
///
/// # Safety
/// As `aloft_mission_plan`, with `out_json` NULL or a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn aloft_mission_json(
    vehicle: *const AloftVehicle,
    mission: *const c_char,
    options_json: *const c_char,
    out_json: *mut *mut c_char,
) -> AloftStatus {
    // SAFETY: the caller's contract; the handle is checked against the registry.
    unsafe {
        with_handle((vehicle, "vehicle"), (out_json, "out_json"), |v, out| {
            let mission = mission_arg(mission)?;
            let (options, scenarios) = match optional_text(options_json, "options_json")? {
                None => (MissionOptions::default(), None),
                Some(t) => options_from_json(t)?,
            };
            let plan = plan_mission(v, &mission, &options)?;
            let json = match scenarios {
                None => plan.to_json()?,
                Some(sc) => MissionWithUncertainty {
                    summary: plan.summary(),
                    uncertainty: &plan_scenarios(v, &mission, &options, &sc)?,
                }
                .to_json()?,
            };
            give_string(json, out)
        })
    }
}

/// The summary of a plan as JSON (exactly `aloft mission --format json` without its final
/// newline) into `*out_json`, released with `aloft_string_free`.
///
/// # Safety
/// `plan` is NULL or a pointer (checked); `out_json` is NULL or a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn aloft_plan_json(
    plan: *const AloftPlan,
    out_json: *mut *mut c_char,
) -> AloftStatus {
    // SAFETY: the caller's contract; the handle is checked against the registry.
    unsafe {
        with_handle((plan, "plan"), (out_json, "out_json"), |p: &Plan, out| {
            give_string(p.to_json()?, out)
        })
    }
}

/// One value of a plan into `*out`: the plan checked against the registry, `out` checked for
/// NULL.
///
/// # Safety
/// `plan` is NULL or a pointer (checked); `out` is NULL or a writable `T`.
unsafe fn plan_value<T>(
    plan: *const AloftPlan,
    out: *mut T,
    out_name: &'static str,
    value: impl FnOnce(&Plan) -> T,
) -> AloftStatus {
    guard(|| {
        // SAFETY: checked against the registry; `out` checked for NULL.
        let p = unsafe { self::plan(plan, "plan")? };
        let out = unsafe { out_value(out, out_name)? };
        *out = value(p);
        Ok(())
    })
}

/// Electrical energy of the planned mission, Wh (the summary's `energy_wh`), into `*out_wh`.
///
/// # Safety
/// `plan` is NULL or a pointer (checked); `out_wh` is NULL or a writable `double`.
#[no_mangle]
pub unsafe extern "C" fn aloft_plan_energy_wh(
    plan: *const AloftPlan,
    out_wh: *mut f64,
) -> AloftStatus {
    // SAFETY: the caller's contract; both pointers are checked.
    unsafe { plan_value(plan, out_wh, "out_wh", |p| p.energy_wh()) }
}

/// Whether the planned mission is feasible (lands with the reserve): 1 or 0 into `*out_feasible`.
///
/// # Safety
/// `plan` is NULL or a pointer (checked); `out_feasible` is NULL or a writable `int`.
#[no_mangle]
pub unsafe extern "C" fn aloft_plan_feasible(
    plan: *const AloftPlan,
    out_feasible: *mut c_int,
) -> AloftStatus {
    // SAFETY: the caller's contract; both pointers are checked.
    unsafe {
        plan_value(plan, out_feasible, "out_feasible", |p| {
            c_int::from(p.summary().feasible)
        })
    }
}

/// Release a plan. NULL is a no-op; a pointer that is not a live plan returns
/// `ALOFT_STATUS_BAD_HANDLE` and is not touched.
///
/// # Safety
/// `plan` is NULL or a pointer; it is checked against the registry before use.
#[no_mangle]
pub unsafe extern "C" fn aloft_plan_free(plan: *mut AloftPlan) -> AloftStatus {
    // SAFETY: checked against the registry before use.
    guard(|| unsafe { release(plan, "plan") })
}

/// Hover and orbit endurance, best-endurance and best-range speeds as JSON (exactly
/// `aloft endurance --format json` without its final newline) into `*out_json`, released with
/// `aloft_string_free`. `options_json` is NULL or a JSON object (`battery`, `payload_kg`, `wind`,
/// `course_deg`, `reserve_percent`, `orbit_radius_m`, `orbit_speed_mps`, `aoa`).
///
/// # Safety
/// `vehicle` is NULL or a pointer (checked); `options_json` is NULL or a NUL-terminated string;
/// `out_json` is NULL or a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn aloft_endurance_json(
    vehicle: *const AloftVehicle,
    options_json: *const c_char,
    out_json: *mut *mut c_char,
) -> AloftStatus {
    // SAFETY: the caller's contract; the handle is checked against the registry.
    unsafe {
        with_handle((vehicle, "vehicle"), (out_json, "out_json"), |v, out| {
            let options = match optional_text(options_json, "options_json")? {
                None => EnduranceOptions::default(),
                Some(t) => EnduranceOptions::from_json(t)?,
            };
            give_string(endurance(v, &options)?.to_json()?, out)
        })
    }
}

/// Release a string returned by aloft. NULL is a no-op; a pointer that aloft did not return, or
/// returned and has freed already, gives `ALOFT_STATUS_BAD_HANDLE` and is not touched.
///
/// # Safety
/// `s` is NULL or a pointer; it is checked against the registry before use.
#[no_mangle]
pub unsafe extern "C" fn aloft_string_free(s: *mut c_char) -> AloftStatus {
    guard(|| {
        if s.is_null() {
            return Ok(());
        }
        if !unregister(s, Kind::String) {
            return Err(not_live("string", Kind::String));
        }
        // SAFETY: it was live (made by CString::into_raw) and is now out of the registry.
        drop(unsafe { CString::from_raw(s) });
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_inside_is_a_status_and_a_message() {
        let s = guard(|| panic!("boom"));
        assert_eq!(s, AloftStatus::Panic);
        // SAFETY: the returned pointer is a valid C string until the next call on this thread.
        let msg = unsafe { CStr::from_ptr(aloft_last_error_message()) };
        assert!(msg.to_str().unwrap().contains("boom"));
        assert_eq!(guard(|| Ok(())), AloftStatus::Ok);
        let msg = unsafe { CStr::from_ptr(aloft_last_error_message()) };
        assert!(msg.to_bytes().is_empty());
    }
}
