//! The vehicles a request may fly (`vehicle=NAME`), each under one name of the page's list
//! (`GET /api/vehicles`, the entries of `aloft vehicles --format json`):
//!
//! - the built-ins, under their names;
//! - the vehicle files given on the command line (positionally or with `--vehicle`), read once
//!   at start: under their own name (the file's `name`), or, when a built-in or an earlier file
//!   has it, under the name the file was given with; a request may name them by either;
//! - the vehicle files sent to `POST /api/vehicles` (a file dropped on the page), kept in memory
//!   under their own name, which may be no built-in's and no given file's (422 naming the clash).
//!   Sending a file of a name already sent replaces that vehicle; past [`MAX_SENT`] vehicles
//!   the oldest is forgotten (a request that names it is then 400, as any unknown name).
//!
//! A vehicle is flown from memory ([`Vehicle`], read once): no request reads a file, and no name
//! a request gives is a path ([`super::given::Names`]).

use std::collections::VecDeque;
use std::sync::{Arc, Mutex};

use anyhow::{Context, Result};
use axum::http::StatusCode;

use aloft::engine::{answers, builtin_names, list_vehicles, Vehicle, VehicleEntry};

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
        };
        for (given_as, vehicle) in files {
            let mut entry = vehicle
                .entry()
                .with_context(|| format!("vehicle file {given_as}"))?;
            if fleet.listed(vehicle.name()).is_some() {
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

    /// The vehicle listed under `name` (by its name in the list only).
    fn listed(&self, name: &str) -> Option<&Listed> {
        self.builtins
            .iter()
            .chain(&self.given)
            .find(|l| l.name() == name)
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

    /// A vehicle sent has a name of its own: not a built-in's nor a given file's (any name a
    /// request may give it), non-empty, short, on one line.
    fn check_name(&self, name: &str, origin: &str) -> Result<(), String> {
        let bad = |why: &str| Err(format!("vehicle file {origin}: its name {why}"));
        if name.trim().is_empty() {
            return bad("is empty");
        }
        if name.len() > MAX_NAME_BYTES {
            return bad(&format!("is longer than {MAX_NAME_BYTES} bytes"));
        }
        if name.chars().any(char::is_control) {
            return bad("holds a control character");
        }
        if builtin_names().contains(&name) {
            return bad(&format!(
                "'{name}' is a built-in vehicle's: give yours a name of its own (`name` in the file)"
            ));
        }
        if self.given.iter().any(|l| l.answers_to(name)) {
            return bad(&format!(
                "'{name}' is a vehicle's given to aloft serve on its command line: give yours \
                 a name of its own (`name` in the file)"
            ));
        }
        Ok(())
    }
}
