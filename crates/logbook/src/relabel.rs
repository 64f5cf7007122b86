//! Renaming a vehicle or a pack after its flights were added ([`Logbook::relabel`]): the key
//! changes everywhere in one transaction, its flights with it; the packs aloft keyed by a
//! vehicle's name (`unknown 3S on quad-1`) follow their vehicle's new name.

use rusqlite::{params, OptionalExtension, TransactionBehavior};

use crate::error::{LogbookError, Result};
use crate::ingest::{check_label, derived_suffix, Logbook};

/// Which keys: vehicles' or packs'.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KeyKind {
    /// A vehicle (`vehicles.key`, `flights.vehicle_key`).
    Vehicle,
    /// A pack (`packs.key`, `flights.pack_key`).
    Pack,
}

impl std::fmt::Display for KeyKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            KeyKind::Vehicle => "vehicle",
            KeyKind::Pack => "pack",
        })
    }
}

type Tx<'a> = rusqlite::Transaction<'a>;

impl Logbook {
    /// Rename the vehicle or pack `old` to `new` (a label: [`check_label`]); its flights follow,
    /// and so do the packs keyed by a renamed vehicle's name. Returns the flights renamed.
    ///
    /// # Errors
    /// `new` is not a label ([`LogbookError::BadLabel`]); no `old` in the logbook
    /// ([`LogbookError::NoSuchKey`]); a `new` already there ([`LogbookError::KeyTaken`]: two
    /// vehicles or packs are not merged by a rename); the database cannot be written. Nothing
    /// changes on an error.
    pub fn relabel(&mut self, kind: KeyKind, old: &str, new: &str) -> Result<usize> {
        let new = check_label(new)?;
        let path = self.path.clone();
        let sql = |source| LogbookError::Sqlite {
            path: path.clone(),
            source,
        };
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(sql)?;
        let table = table_of(kind);
        let exists = |tx: &Tx<'_>, key: &str| -> rusqlite::Result<bool> {
            tx.query_row(
                &format!("SELECT 1 FROM {table} WHERE key = ?1"),
                [key],
                |_| Ok(()),
            )
            .optional()
            .map(|r| r.is_some())
        };
        if !exists(&tx, old).map_err(sql)? {
            return Err(LogbookError::NoSuchKey {
                path: self.path.clone(),
                kind,
                key: old.to_string(),
            });
        }
        if old != new && exists(&tx, &new).map_err(sql)? {
            return Err(LogbookError::KeyTaken {
                path: self.path.clone(),
                kind,
                key: new,
            });
        }
        let n = match kind {
            KeyKind::Pack => rename_pack(&tx, old, &new, "label"),
            KeyKind::Vehicle => rename_vehicle(&tx, old, &new),
        }
        .map_err(sql)?;
        tx.commit().map_err(sql)?;
        Ok(n)
    }
}

fn table_of(kind: KeyKind) -> &'static str {
    match kind {
        KeyKind::Vehicle => "vehicles",
        KeyKind::Pack => "packs",
    }
}

/// Pack `old` becomes `new` (`source` its new key source); where `new` is already a pack (a
/// derived key that now names the same kind of pack on the same vehicle) the two are one.
fn rename_pack(tx: &Tx<'_>, old: &str, new: &str, source: &str) -> rusqlite::Result<usize> {
    tx.execute(
        "INSERT OR IGNORE INTO packs (key, key_source, rated_capacity_mah, first_added_unix_s,
                                      cells_series)
         SELECT ?2, ?3, rated_capacity_mah, first_added_unix_s, cells_series
         FROM packs WHERE key = ?1",
        params![old, new, source],
    )?;
    let n = tx.execute(
        "UPDATE flights SET pack_key = ?2 WHERE pack_key = ?1",
        params![old, new],
    )?;
    if old != new {
        tx.execute("DELETE FROM packs WHERE key = ?1", [old])?;
    }
    Ok(n)
}

/// Vehicle `old` becomes `new` (a label), and each pack keyed `... on <old>` becomes
/// `... on <new>`.
fn rename_vehicle(tx: &Tx<'_>, old: &str, new: &str) -> rusqlite::Result<usize> {
    tx.execute(
        "INSERT OR IGNORE INTO vehicles (key, key_source, first_added_unix_s)
         SELECT ?2, 'label', first_added_unix_s FROM vehicles WHERE key = ?1",
        params![old, new],
    )?;
    let n = tx.execute(
        "UPDATE flights SET vehicle_key = ?2 WHERE vehicle_key = ?1",
        params![old, new],
    )?;
    if old != new {
        tx.execute("DELETE FROM vehicles WHERE key = ?1", [old])?;
    }
    let derived: Vec<String> = {
        let mut st = tx.prepare("SELECT key FROM packs WHERE key_source = 'derived'")?;
        let keys = st.query_map([], |r| r.get::<_, String>(0))?;
        keys.collect::<rusqlite::Result<_>>()?
    };
    let (from, to) = (derived_suffix(old), derived_suffix(new));
    for key in derived {
        if let Some(kind) = key.strip_suffix(&from) {
            rename_pack(tx, &key, &format!("{kind}{to}"), "derived")?;
        }
    }
    Ok(n)
}
