//! The vehicles a request may fly (`vehicle=NAME`), each under one name of the page's list
//! (`GET /api/vehicles`, the entries of `aloft vehicles --format json`):
//!
//! - the built-ins, under their names;
//! - the vehicle files given on the command line (positionally or with `--vehicle`), read once
//!   at start: under their own name (the file's `name`), or, when a built-in or an earlier file
//!   has it or one that looks the same ([`looks_like`]), under the name the file was given with;
//!   a request may name them by either. A name no vehicle may have ([`name_fault`]) stops the
//!   server at its start;
//! - the vehicle files sent to `POST /api/vehicles` (a file dropped on the page), kept in memory
//!   under their own name, which may be no built-in's and no given file's, nor look like one,
//!   nor look like another sent's without being it (422 naming the clash); a name no vehicle may
//!   have is refused alike. Sending a file of a name already sent replaces that vehicle; past
//!   [`MAX_SENT`] vehicles the oldest is forgotten (a request that names it is then 400, as any
//!   unknown name).
//!
//! Two names look the same when they differ only by case, by their spaces, by a dash for a
//! hyphen (U+2010 HYPHEN and its kin), or by a full-width letter for its ASCII one; a name is
//! refused when it is empty, long, starts or ends with a space, or holds a control character or
//! an invisible one (a zero width space, a right-to-left override and the other format
//! characters), which would make two names that read the same in the list.
//!
//! A vehicle is flown from memory ([`Vehicle`], read once): no request reads a file, and no name
//! a request gives is a path ([`super::given::Names`]).

use std::collections::VecDeque;
use std::sync::{Arc, Mutex};

use anyhow::{Context, Result};
use axum::http::StatusCode;

use aloft::engine::{answers, fly_with_battery, list_vehicles, Failsafe, Vehicle, VehicleEntry};

use super::{engine_message, error, Refused};

/// Most vehicles sent to `POST /api/vehicles` kept at once: past it the oldest is forgotten.
pub(super) const MAX_SENT: usize = 32;

/// Longest name of a vehicle sent, bytes.
const MAX_NAME_BYTES: usize = 100;

/// A vehicle of the list.
#[derive(Clone)]
struct Listed {
    /// Its entry, under its name in the list (the name a request gives).
    entry: VehicleEntry,
    /// The name its file was given with on the command line, when it was.
    given_as: Option<String>,
    /// The vehicle.
    vehicle: Arc<Vehicle>,
}

impl Listed {
    fn name(&self) -> &str {
        &self.entry.name
    }

    /// Whether a request's `vehicle=value` names it.
    fn answers_to(&self, value: &str) -> bool {
        self.name() == value
            || self.vehicle.name() == value
            || self.given_as.as_deref() == Some(value)
    }
}

/// The vehicles of the server.
pub(super) struct Fleet {
    /// The built-ins, in `aloft vehicles`'s order.
    builtins: Vec<Listed>,
    /// The vehicle files given on the command line, in order.
    given: Vec<Listed>,
    /// The vehicles sent, oldest first.
    sent: Mutex<VecDeque<Listed>>,
    /// The vehicle a request flies when it names none (the first `--vehicle`).
    default: Listed,
    /// The pack of `--battery`, flown by the default vehicle when a request names none.
    default_pack: Option<DefaultPack>,
}

/// The pack of `aloft serve --battery`.
#[derive(Debug, Clone)]
pub(super) struct DefaultPack {
    /// Its name among the default vehicle's packs.
    pub(super) name: String,
    /// A pack file's failsafes (the options' own come first).
    pub(super) failsafe: Option<Failsafe>,
}

impl Fleet {
    /// The built-ins and the vehicle files given (each with the name it was given with); `default` (the first `--vehicle`, a
    /// built-in's name or a given file's name) is the vehicle of requests that name none.
    ///
    /// # Errors
    /// A vehicle file that no command can fly (no default take-off mass), named.
    pub(super) fn new(files: &[(String, Arc<Vehicle>)], default: &str) -> Result<Self> {
        let builtins = list_vehicles()?
            .into_iter()
            .map(|entry| {
                Ok(Listed {
                    vehicle: Arc::new(Vehicle::builtin(&entry.name)?),
                    entry,
                    given_as: None,
                })
            })
            .collect::<Result<Vec<_>, aloft::Error>>()?;
        let mut fleet = Self {
            default: builtins[0].clone(),
            builtins,
            given: Vec::new(),
            sent: Mutex::new(VecDeque::new()),
            default_pack: None,
        };
        for (given_as, vehicle) in files {
            if let Some(why) = name_fault(vehicle.name()) {
                anyhow::bail!("vehicle file {given_as}: its name {why}");
            }
            let mut entry = vehicle
                .entry()
                .with_context(|| format!("vehicle file {given_as}"))?;
            if fleet.listed_like(vehicle.name()).is_some() {
                entry.name.clone_from(given_as);
            }
            fleet.given.push(Listed {
                entry,
                given_as: Some(given_as.clone()),
                vehicle: vehicle.clone(),
            });
        }
        fleet.default = fleet
            .resolve(default)
            .with_context(|| format!("--vehicle {default}: not a vehicle of the server"))?;
        Ok(fleet)
    }

    /// The built-in or given vehicle whose name in the list, own name or given name looks like
    /// `name` ([`looks_like`]).
    fn listed_like(&self, name: &str) -> Option<&Listed> {
        self.builtins.iter().chain(&self.given).find(|l| {
            looks_like(l.name(), name)
                || looks_like(l.vehicle.name(), name)
                || l.given_as.as_deref().is_some_and(|g| looks_like(g, name))
        })
    }

    /// The vehicle a request's `vehicle=value` names: a built-in, a given file (by its name in
    /// the list, its own name or the name it was given with), a vehicle sent.
    fn resolve(&self, value: &str) -> Option<Listed> {
        if let Some(b) = self.builtins.iter().find(|l| l.name() == value) {
            return Some(b.clone());
        }
        if let Some(g) = self.given.iter().find(|l| l.answers_to(value)) {
            return Some(g.clone());
        }
        self.sent
            .lock()
            .ok()?
            .iter()
            .find(|l| l.name() == value)
            .cloned()
    }

    /// The name in the list of the vehicle `value` names, if any.
    pub(super) fn resolve_name(&self, value: &str) -> Option<String> {
        self.resolve(value).map(|l| l.entry.name)
    }

    /// The vehicle `name` names, or the 400 of a vehicle forgotten since (see [`MAX_SENT`]).
    pub(super) fn vehicle(&self, request: &str, name: &str) -> Result<Arc<Vehicle>, Refused> {
        self.resolve(name).map(|l| l.vehicle).ok_or_else(|| {
            Refused::from(error(
                StatusCode::BAD_REQUEST,
                &format!("'vehicle' of {request} names '{name}', a vehicle no longer kept"),
            ))
        })
    }

    /// The name in the list of the vehicle of requests that name none.
    pub(super) fn default_name(&self) -> &str {
        self.default.name()
    }

    /// Fly the default vehicle with `battery` (`aloft serve --battery`): one of its packs by
    /// name, or a pack file added to its packs (replacing one of the same name), as the command
    /// line's `--battery` flies it ([`fly_with_battery`]). Requests that fly the default vehicle
    /// and name no pack fly it ([`Self::default_pack`]); its entry in the list names it.
    ///
    /// # Errors
    /// A value that is neither a pack of the vehicle's nor a pack file it can fly, named.
    pub(super) fn fly_default_with(&mut self, battery: &str) -> Result<()> {
        let vehicle = self.default.vehicle.as_ref().clone();
        let flying = fly_with_battery(vehicle, Some(battery))
            .map_err(|e| anyhow::anyhow!("--battery {battery}: {}", engine_message(e)))?;
        let name = flying
            .battery
            .clone()
            .unwrap_or_else(|| battery.to_string());
        if let Err(e) = flying.vehicle.battery(Some(&name)) {
            anyhow::bail!(
                "--battery {battery}: neither a pack of {} nor a pack file: {}",
                self.default.name(),
                engine_message(e)
            );
        }
        let listed_as = self.default.name().to_string();
        let mut entry = flying.vehicle.entry()?;
        entry.name.clone_from(&listed_as);
        let vehicle = Arc::new(flying.vehicle);
        let same = |l: &&mut Listed| l.name() == listed_as;
        for l in self.builtins.iter_mut().chain(&mut self.given).filter(same) {
            l.vehicle = vehicle.clone();
            l.entry = entry.clone();
        }
        self.default.vehicle = vehicle;
        self.default.entry = entry;
        self.default_pack = Some(DefaultPack {
            name,
            failsafe: flying.failsafe,
        });
        Ok(())
    }

    /// The pack of `--battery` when `vehicle` (a name in the list) is the default vehicle.
    pub(super) fn default_pack(&self, vehicle: &str) -> Option<&DefaultPack> {
        self.default_pack
            .as_ref()
            .filter(|_| vehicle == self.default.name())
    }

    /// The vehicle of requests that name none, and the one `--live` / `--tlog` follow.
    pub(super) fn default_vehicle(&self) -> Arc<Vehicle> {
        self.default.vehicle.clone()
    }

    /// The names of the list, in its order.
    pub(super) fn names(&self) -> Vec<String> {
        self.entries().into_iter().map(|e| e.name).collect()
    }

    /// The list: the built-ins, the given vehicle files, the vehicles sent.
    pub(super) fn entries(&self) -> Vec<VehicleEntry> {
        let sent = self.sent.lock().map(|s| s.clone()).unwrap_or_default();
        self.builtins
            .iter()
            .chain(&self.given)
            .chain(&sent)
            .map(|l| l.entry.clone())
            .collect()
    }

    /// Keep a vehicle sent (its file's text, `origin` naming it in messages): its entry's JSON,
    /// or the message of a 422.
    pub(super) fn keep(&self, text: &[u8], origin: &str) -> Result<String, String> {
        let text = std::str::from_utf8(text).map_err(|_| {
            engine_message(aloft::Error::VehicleFormat {
                origin: origin.to_string(),
                message: "not UTF-8 text".to_string(),
            })
        })?;
        let vehicle = Vehicle::from_toml(text, origin).map_err(engine_message)?;
        let name = vehicle.name().to_string();
        self.check_name(&name, origin)?;
        let entry = vehicle.entry().map_err(engine_message)?;
        let answer = answers::vehicle_answer(&vehicle, &name).map_err(engine_message)?;
        let mut sent = self.sent.lock().map_err(|_| "the vehicles' list failed")?;
        if let Some(other) = sent
            .iter()
            .find(|l| l.name() != name && looks_like(l.name(), &name))
        {
            return Err(format!(
                "vehicle file {origin}: its name '{name}' looks like that of a vehicle sent \
                 before, '{}': give yours a name of its own (`name` in the file)",
                other.name()
            ));
        }
        sent.retain(|l| l.name() != name);
        if sent.len() == MAX_SENT {
            sent.pop_front();
        }
        sent.push_back(Listed {
            entry,
            given_as: None,
            vehicle: Arc::new(vehicle),
        });
        Ok(answer)
    }

    /// A vehicle sent has a name of its own: one a vehicle may have ([`name_fault`]), not a
    /// built-in's nor a given file's (any name a request may give it), nor one that looks like
    /// them ([`looks_like`]).
    fn check_name(&self, name: &str, origin: &str) -> Result<(), String> {
        let bad = |why: &str| Err(format!("vehicle file {origin}: its name {why}"));
        if let Some(why) = name_fault(name) {
            return bad(&why);
        }
        let Some(taken) = self.listed_like(name) else {
            return Ok(());
        };
        let whose = match taken.given_as {
            None => "a built-in vehicle's",
            Some(_) => "a vehicle's given to aloft serve on its command line",
        };
        let taken = taken.name();
        match taken == name {
            true => bad(&format!(
                "'{name}' is {whose}: give yours a name of its own (`name` in the file)"
            )),
            false => bad(&format!(
                "'{name}' looks like '{taken}', {whose}: give yours a name of its own (`name` \
                 in the file)"
            )),
        }
    }
}

/// Why `name` cannot name a vehicle of the list, if it cannot (module docs): empty, longer than
/// [`MAX_NAME_BYTES`], a space at either end, a control or an invisible character.
fn name_fault(name: &str) -> Option<String> {
    if name.trim().is_empty() {
        return Some("is empty".to_string());
    }
    if name.len() > MAX_NAME_BYTES {
        return Some(format!("is longer than {MAX_NAME_BYTES} bytes"));
    }
    if name.trim() != name {
        return Some("starts or ends with a space".to_string());
    }
    if name.chars().any(char::is_control) {
        return Some("holds a control character".to_string());
    }
    if let Some(c) = name.chars().find(|c| invisible(*c)) {
        return Some(format!(
            "holds an invisible character (U+{:04X}), which makes it read as another",
            u32::from(c)
        ));
    }
    None
}

/// Characters that show nothing (or turn the text around) where they stand: Unicode's format
/// characters (zero width spaces and joiners, direction marks, embeddings, overrides and
/// isolates, the byte order mark, tags), variation selectors and the fillers that render blank.
fn invisible(c: char) -> bool {
    matches!(
        u32::from(c),
        0x00AD
            | 0x034F
            | 0x061C
            | 0x115F..=0x1160
            | 0x17B4..=0x17B5
            | 0x180B..=0x180F
            | 0x200B..=0x200F
            | 0x202A..=0x202E
            | 0x2060..=0x206F
            | 0x3164
            | 0xFE00..=0xFE0F
            | 0xFEFF
            | 0xFFA0
            | 0xFFF0..=0xFFFB
            | 0x1D173..=0x1D17A
            | 0xE0000..=0xE0FFF
    )
}

/// Whether two names read the same in the list: equal once each is folded ([`folded`]).
fn looks_like(a: &str, b: &str) -> bool {
    folded(a) == folded(b)
}

/// A name as it reads: lower case; every dash and hyphen (U+2010-U+2015, U+2212, U+FE58,
/// U+FE63) as `-`; full-width ASCII (U+FF01-U+FF5E) as ASCII; each run of spaces (any Unicode
/// white space) as one, none at the ends; invisible characters left out.
fn folded(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    let mut space = false;
    for c in name.chars().filter(|c| !invisible(*c)) {
        let c = match u32::from(c) {
            0x2010..=0x2015 | 0x2212 | 0xFE58 | 0xFE63 => '-',
            0xFF01..=0xFF5E => char::from_u32(u32::from(c) - 0xFEE0).unwrap_or(c),
            _ => c,
        };
        if c.is_whitespace() {
            space = !out.is_empty();
            continue;
        }
        if space {
            out.push(' ');
            space = false;
        }
        out.extend(c.to_lowercase());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_read_the_same_fold_to_one() {
        for (a, b) in [
            ("dji-m100", "DJI-M100"),
            ("dji-m100", "dji\u{2010}m100"),
            ("dji-m100", "dji\u{2212}m100"),
            ("my quad", "my\u{00A0}\u{00A0}quad"),
            ("my-quad", "\u{FF4D}y-quad"),
            ("my-quad", "my-\u{200B}quad"),
        ] {
            assert!(looks_like(a, b), "{a:?} {b:?}");
        }
        for (a, b) in [
            ("dji-m100", "dji-m600"),
            ("my-quad", "my_quad"),
            ("quad", "quads"),
        ] {
            assert!(!looks_like(a, b), "{a:?} {b:?}");
        }
    }

    #[test]
    fn names_that_hide_what_they_are_are_refused() {
        for bad in [
            "",
            "  ",
            "quad ",
            " quad",
            "quad\u{00A0}",
            "qu\u{200B}ad",
            "\u{202E}dauq",
            "quad\u{FE0F}",
            "a\tb",
        ] {
            assert!(name_fault(bad).is_some(), "{bad:?}");
        }
        for good in ["my quad", "Quad-7 (2024)", "квадрокоптер", "<b>x</b>"] {
            assert_eq!(name_fault(good), None, "{good:?}");
        }
        assert!(name_fault(&"x".repeat(101)).is_some());
    }
}
