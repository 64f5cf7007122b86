//! DO_JUMP (MAV_CMD 177) unrolled into the flying order.
//!
//! A DO_JUMP sends the mission back (or forward) to its target `p1` times `p2`; after the last
//! repeat the mission goes on past it. Its counter is never reset (ArduPilot's `AP_Mission`
//! jump tracking and PX4's `do_jump_current_count` both keep it for the whole mission), so a
//! jump nested in a repeated loop repeats only the first time round. The target is a `doJumpId`
//! in a `.plan` and a row INDEX in a `.waypoints` file.
//!
//! The unrolled route is bounded: the jumps may add at most [`MAX_REPEATED_ITEMS`] passes of
//! items (jumps included) to the file's own; beyond it the file is refused at the item where the
//! limit was passed. A file without jumps is not bounded here (the planner bounds its segments).
//! A repeat count of -1 (for ever) is refused.

use crate::commands::DO_JUMP;
use crate::error::ImportError;
use crate::notes::Notes;
use crate::raw_item::RawItem;

/// Most passes of items the jumps may add to the route: 20,000 (a survey of a 500 KB `.plan`
/// has about 2,000 items); each becomes up to three segments, and the planner takes 50,000.
pub const MAX_REPEATED_ITEMS: usize = 20_000;

/// How a DO_JUMP names its target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum JumpsBy {
    /// A `.plan`: the target item's `doJumpId`.
    DoJumpId,
    /// A `.waypoints` file: the target row's INDEX (row 0, home, means the first item).
    RowIndex,
}

/// A DO_JUMP resolved: the index of its target in the item list and its repeat count.
#[derive(Debug, Clone, Copy)]
struct Jump {
    target: usize,
    repeats: u64,
}

/// The indices of `items` in flying order, DO_JUMP items included where they are passed.
///
/// # Errors
/// [`ImportError::JumpTarget`], [`ImportError::EndlessJump`], [`ImportError::TooManyItems`].
pub(crate) fn flying_order(
    items: &[RawItem],
    by: JumpsBy,
    notes: &mut Notes,
) -> Result<Vec<usize>, ImportError> {
    let mut jumps = Vec::with_capacity(items.len());
    for item in items {
        jumps.push(if item.command == DO_JUMP {
            Some(resolve(item, items, by, notes)?)
        } else {
            None
        });
    }
    let mut left: Vec<u64> = jumps.iter().map(|j| j.map_or(0, |j| j.repeats)).collect();
    let mut order = Vec::with_capacity(items.len());
    let mut pc = 0;
    while pc < items.len() {
        if order.len() == items.len() + MAX_REPEATED_ITEMS {
            return Err(ImportError::TooManyItems {
                at: items[pc].at,
                limit: MAX_REPEATED_ITEMS,
            });
        }
        order.push(pc);
        match jumps[pc] {
            Some(j) if left[pc] > 0 => {
                left[pc] -= 1;
                pc = j.target;
            }
            _ => pc += 1,
        }
    }
    Ok(order)
}

/// The target and repeat count of the DO_JUMP `item`.
fn resolve(
    item: &RawItem,
    items: &[RawItem],
    by: JumpsBy,
    notes: &mut Notes,
) -> Result<Jump, ImportError> {
    let [target, repeat, ..] = item.params;
    if !(repeat.is_finite() && repeat >= 0.0 && repeat.fract() == 0.0) {
        return Err(ImportError::EndlessJump {
            at: item.at,
            repeat,
        });
    }
    // Beyond the limit any count is refused alike; keep the integer small.
    let repeats = repeat.min(MAX_REPEATED_ITEMS as f64 + 1.0) as u64;
    let whole = target.is_finite() && target.fract() == 0.0 && target.abs() < 1e9;
    let found = whole
        .then(|| match by {
            JumpsBy::DoJumpId => find_jump_id(item, items, target as i64, notes),
            JumpsBy::RowIndex if target.abs() < 0.5 => {
                notes.add(item.at, "DO_JUMP to row 0 (home) jumps to the first item");
                (!items.is_empty()).then_some(0)
            }
            JumpsBy::RowIndex => items
                .iter()
                .position(|x| i64::from(x.number) == target as i64),
        })
        .flatten();
    match found {
        Some(t) => Ok(Jump { target: t, repeats }),
        None => Err(ImportError::JumpTarget {
            at: item.at,
            target,
            kind: match by {
                JumpsBy::DoJumpId => "a doJumpId",
                JumpsBy::RowIndex => "a row INDEX",
            },
        }),
    }
}

/// The first item with `doJumpId` `id`; a warning when several have it.
fn find_jump_id(item: &RawItem, items: &[RawItem], id: i64, notes: &mut Notes) -> Option<usize> {
    let mut matches = items
        .iter()
        .enumerate()
        .filter(|(_, x)| x.jump_id == Some(id));
    let first = matches.next().map(|(k, _)| k);
    if first.is_some() && matches.next().is_some() {
        notes.add(
            item.at,
            format!("DO_JUMP target doJumpId {id} is on several items: the first is taken"),
        );
    }
    first
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Place;

    fn item(number: u32, command: u32, p1: f64, p2: f64) -> RawItem {
        RawItem {
            at: Place::Row(number),
            number,
            command,
            frame: 3,
            params: [p1, p2, 0.0, 0.0, 0.0, 0.0, 10.0],
            jump_id: Some(i64::from(number)),
        }
    }

    #[test]
    fn a_jump_repeats_its_loop_and_nested_counters_are_not_reset() {
        // 1, 2, [3: jump to 2 once], 4, [5: jump to 1 once]
        let items = [
            item(1, 16, 0.0, 0.0),
            item(2, 16, 0.0, 0.0),
            item(3, DO_JUMP, 2.0, 1.0),
            item(4, 16, 0.0, 0.0),
            item(5, DO_JUMP, 1.0, 1.0),
        ];
        let order = flying_order(&items, JumpsBy::RowIndex, &mut Notes::default()).unwrap();
        let numbers: Vec<u32> = order.iter().map(|&k| items[k].number).collect();
        // The inner jump (3) has used its repeat on the first pass: it is passed the second time.
        assert_eq!(numbers, [1, 2, 3, 2, 3, 4, 5, 1, 2, 3, 4, 5]);
    }

    /// Regression (issue 32): a plan of 20,000 waypoints and no DO_JUMP was refused as "a loop
    /// repeated too often": the bound is on what the jumps add.
    #[test]
    fn a_long_route_without_jumps_is_not_a_loop() {
        let items: Vec<RawItem> = (1..=25_000).map(|n| item(n, 16, 0.0, 0.0)).collect();
        let order = flying_order(&items, JumpsBy::RowIndex, &mut Notes::default()).unwrap();
        assert_eq!(order.len(), 25_000);
        // With a loop, the jumps may add 20,000 passes and no more.
        let mut looped = items[..100].to_vec();
        // 197 repeats: 101 x 198 = 19,998 passes, 19,897 of them added.
        looped.push(item(101, DO_JUMP, 1.0, 197.0));
        let order = flying_order(&looped, JumpsBy::RowIndex, &mut Notes::default()).unwrap();
        assert_eq!(order.len(), 101 * 198);
        // 199 repeats: 20,200 passes, 20,099 added.
        looped[100] = item(101, DO_JUMP, 1.0, 199.0);
        assert!(flying_order(&looped, JumpsBy::RowIndex, &mut Notes::default()).is_err());
    }

    #[test]
    fn endless_and_huge_loops_and_missing_targets_are_refused_naming_the_item() {
        let endless = [item(1, 16, 0.0, 0.0), item(2, DO_JUMP, 1.0, -1.0)];
        let e = flying_order(&endless, JumpsBy::RowIndex, &mut Notes::default()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("row 2 (command 177 DO_JUMP): param2"),
            "{e}"
        );
        let huge = [item(1, 16, 0.0, 0.0), item(2, DO_JUMP, 1.0, 1e12)];
        let e = flying_order(&huge, JumpsBy::RowIndex, &mut Notes::default()).unwrap_err();
        assert!(
            matches!(
                e,
                ImportError::TooManyItems {
                    limit: MAX_REPEATED_ITEMS,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("row "), "{e}");
        let nowhere = [item(1, 16, 0.0, 0.0), item(2, DO_JUMP, 7.0, 1.0)];
        let e = flying_order(&nowhere, JumpsBy::DoJumpId, &mut Notes::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "row 2 (command 177 DO_JUMP): param1 target 7 is not a doJumpId in the file"
        );
        let nan = [item(1, 16, 0.0, 0.0), item(2, DO_JUMP, 1.0, f64::NAN)];
        assert!(flying_order(&nan, JumpsBy::RowIndex, &mut Notes::default()).is_err());
    }
}
