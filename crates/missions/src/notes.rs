//! Warnings gathered while a file is read, one line per message with every place it applies to
//! (`items 3-5, 9: terrain-relative altitude (frame 10) flown as relative to home`), so that a
//! survey of hundreds of items gives a few readable lines; a note about the whole file has no
//! place.

use crate::error::Place;

/// Warnings in the order they first occurred, each with its places.
#[derive(Debug, Default)]
pub(crate) struct Notes {
    entries: Vec<(String, Vec<Place>)>,
}

impl Notes {
    /// `message` applies to `at` (once per place).
    pub(crate) fn add(&mut self, at: Place, message: impl Into<String>) {
        let message = message.into();
        match self.entries.iter_mut().find(|(m, _)| *m == message) {
            Some((_, places)) => {
                if !places.contains(&at) {
                    places.push(at);
                }
            }
            None => self.entries.push((message, vec![at])),
        }
    }

    /// The warnings as lines.
    pub(crate) fn finish(self) -> Vec<String> {
        self.entries
            .into_iter()
            .map(|(message, places)| {
                if places.iter().all(|p| *p == Place::File) {
                    message
                } else {
                    format!("{}: {message}", places_text(&places))
                }
            })
            .collect()
    }
}

/// `item 3`, `items 3-5, 9`, `rows 1, 4`, `file`.
pub(crate) fn places_text(places: &[Place]) -> String {
    let numbers: Vec<u32> = places
        .iter()
        .filter_map(|p| match p {
            Place::Item(n) | Place::Row(n) => Some(*n),
            _ => None,
        })
        .collect();
    if numbers.len() != places.len() || numbers.is_empty() {
        return places
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(", ");
    }
    let word = match places[0] {
        Place::Row(_) => "row",
        _ => "item",
    };
    let plural = if numbers.len() > 1 { "s" } else { "" };
    format!("{word}{plural} {}", ranges(numbers))
}

/// `3-5, 9` of 3, 4, 5, 9 (sorted, repeats once).
fn ranges(mut numbers: Vec<u32>) -> String {
    numbers.sort_unstable();
    numbers.dedup();
    let mut parts = Vec::new();
    let mut k = 0;
    while k < numbers.len() {
        let start = numbers[k];
        let mut end = start;
        while k + 1 < numbers.len() && numbers[k + 1] == end + 1 {
            k += 1;
            end = numbers[k];
        }
        parts.push(if end == start {
            start.to_string()
        } else {
            format!("{start}-{end}")
        });
        k += 1;
    }
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn notes_group_places_into_ranges() {
        let mut n = Notes::default();
        for i in [3, 4, 5, 9, 4] {
            n.add(Place::Item(i), "terrain");
        }
        n.add(Place::Row(2), "other");
        n.add(Place::File, "whole");
        assert_eq!(
            n.finish(),
            ["items 3-5, 9: terrain", "row 2: other", "whole"]
        );
    }
}
