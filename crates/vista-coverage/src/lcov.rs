//! Counter values mapped to files and lines, summed over runs, as LCOV.

use std::collections::BTreeMap;
use std::fmt::Write;

use crate::Counter;

/// Where a span starts in the user's files.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct Place {
    /// The file as the report names it (relative to the project).
    pub file: String,
    /// 1-based line.
    pub line: u32,
    /// 1-based column.
    pub col: u32,
}

/// A branch arm's key: its statement's line and column (the block), and
/// the arm.
type ArmKey = (u32, u32, u32);

/// Hit counts per file: lines, and branch arms (`None`: the branching
/// statement never ran).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Counts {
    lines: BTreeMap<String, BTreeMap<u32, u64>>,
    arms: BTreeMap<String, BTreeMap<ArmKey, u64>>,
    /// Per file, each function by its declaration's line and name: its
    /// calls (one name may be declared on several lines: WESL `@if`
    /// alternatives, `#ifdef` branches).
    functions: BTreeMap<String, BTreeMap<(u32, String), u64>>,
}

impl Counts {
    /// Adds one run's counter `values` (element i for counter i), each
    /// statement's line taking the largest count of the segments on it (a
    /// line runs as often as its most-run statement); a span `place`
    /// cannot map (a generated statement) counts nowhere.
    pub fn add(&mut self, counters: &[Counter], values: &[u32], place: &dyn Fn(naga::Span) -> Option<Place>) {
        let mut run_lines: BTreeMap<(String, u32), u64> = BTreeMap::new();
        // A derived counter names only earlier ones: one pass in order.
        let mut value: Vec<u32> = Vec::with_capacity(counters.len());
        for (i, c) in counters.iter().enumerate() {
            let v = match c.derived {
                Some((whole, part)) => value[whole].saturating_sub(value[part]),
                None => values.get(i).copied().unwrap_or(0),
            };
            value.push(v);
            for p in c.spans.iter().filter_map(|s| place(*s)) {
                let hits = run_lines.entry((p.file, p.line)).or_default();
                *hits = (*hits).max(v as u64);
            }
            if let Some(arm) = c.arm
                && let Some(p) = place(arm.at)
            {
                *self.arms.entry(p.file).or_default().entry((p.line, p.col, arm.branch)).or_default() += v as u64;
            }
        }
        for ((file, line), hits) in run_lines {
            *self.lines.entry(file).or_default().entry(line).or_default() += hits;
        }
    }

    /// Adds one run's calls of each function: `(declaration, name, its
    /// first counter)`, the counter that counts its body's start.
    pub fn add_functions(&mut self, functions: &[(Place, String, usize)], values: &[u32]) {
        for (at, name, counter) in functions {
            let calls = values.get(*counter).copied().unwrap_or(0) as u64;
            *self.functions.entry(at.file.clone()).or_default().entry((at.line, name.clone())).or_default() += calls;
        }
    }

    /// Adds another run's (or shard's) counts.
    pub fn merge(&mut self, other: &Counts) {
        for (file, functions) in &other.functions {
            let mine = self.functions.entry(file.clone()).or_default();
            for (key, calls) in functions {
                *mine.entry(key.clone()).or_default() += calls;
            }
        }
        for (file, lines) in &other.lines {
            let mine = self.lines.entry(file.clone()).or_default();
            for (line, hits) in lines {
                *mine.entry(*line).or_default() += hits;
            }
        }
        for (file, arms) in &other.arms {
            let mine = self.arms.entry(file.clone()).or_default();
            for (key, hits) in arms {
                *mine.entry(*key).or_default() += hits;
            }
        }
    }

    /// The hit count of each measured line of `file`, in line order.
    pub fn lines(&self, file: &str) -> Vec<(u32, u64)> {
        self.lines.get(file).map(|l| l.iter().map(|(k, v)| (*k, *v)).collect()).unwrap_or_default()
    }

    /// Each arm of `file`: (line, column, arm, hits), in line order.
    pub fn arms(&self, file: &str) -> Vec<(u32, u32, u32, u64)> {
        self.arms.get(file).map(|a| a.iter().map(|(k, v)| (k.0, k.1, k.2, *v)).collect()).unwrap_or_default()
    }

    /// The files with measured lines.
    pub fn files(&self) -> Vec<String> {
        self.lines.keys().cloned().collect()
    }

    /// Lines found and hit, arms found and taken, over every file.
    pub fn totals(&self) -> (usize, usize, usize, usize) {
        let lines = self.lines.values().flat_map(|l| l.values());
        let arms = self.arms.values().flat_map(|a| a.values());
        let (lf, lh) = lines.fold((0, 0), |(f, h), &v| (f + 1, h + usize::from(v > 0)));
        let (bf, bh) = arms.fold((0, 0), |(f, h), &v| (f + 1, h + usize::from(v > 0)));
        (lf, lh, bf, bh)
    }

    /// Counts read back from an LCOV tracefile this crate wrote (a case's,
    /// a shard's): `SF`, `DA` and `BRDA` lines; an arm whose statement
    /// never ran (`-`) counts 0. Other records are skipped.
    pub fn from_lcov(text: &str) -> Counts {
        let mut counts = Counts::default();
        let mut file = String::new();
        // A function's name as written (see `lcov`) to its key.
        let mut written: BTreeMap<String, (u32, String)> = BTreeMap::new();
        for line in text.lines() {
            let numbers = |rest: &str| -> Vec<u64> { rest.split(',').map(|n| n.parse().unwrap_or(0)).collect() };
            if let Some(f) = line.strip_prefix("SF:") {
                file = f.to_string();
                written.clear();
                counts.lines.entry(file.clone()).or_default();
            } else if let Some(rest) = line.strip_prefix("DA:") {
                if let [l, hits, ..] = numbers(rest)[..] {
                    *counts.lines.entry(file.clone()).or_default().entry(l as u32).or_default() += hits;
                }
            } else if let Some((l, name)) = line.strip_prefix("FN:").and_then(|r| r.split_once(',')) {
                let at: u32 = l.parse().unwrap_or(0);
                let base = name.strip_suffix(&format!("@{at}")).unwrap_or(name);
                let key = (at, base.to_string());
                counts.functions.entry(file.clone()).or_default().entry(key.clone()).or_default();
                written.insert(name.to_string(), key);
            } else if let Some((calls, name)) = line.strip_prefix("FNDA:").and_then(|r| r.split_once(',')) {
                let calls: u64 = calls.parse().unwrap_or(0);
                if let Some(key) = written.get(name) {
                    *counts.functions.entry(file.clone()).or_default().entry(key.clone()).or_default() += calls;
                }
            } else if let Some(rest) = line.strip_prefix("BRDA:")
                && let [l, col, arm, hits] = numbers(rest)[..]
            {
                let key = (l as u32, col as u32, arm as u32);
                *counts.arms.entry(file.clone()).or_default().entry(key).or_default() += hits;
            }
        }
        counts
    }

    /// Drops `file`'s lines and arms after line `last`: code appended to a
    /// user's file (a test runner's entry points) that the file does not show.
    pub fn keep_lines(&mut self, file: &str, last: u32) {
        if let Some(lines) = self.lines.get_mut(file) {
            lines.retain(|&l, _| l <= last);
        }
        if let Some(arms) = self.arms.get_mut(file) {
            arms.retain(|k, _| k.0 <= last);
        }
        if let Some(functions) = self.functions.get_mut(file) {
            functions.retain(|k, _| k.0 <= last);
        }
    }

    /// Whether nothing was measured.
    pub fn is_empty(&self) -> bool {
        self.lines.values().all(|l| l.is_empty())
    }

    /// The LCOV tracefile (`lcov.info`): per file `SF`, `FN`/`FNDA` per
    /// function (its declaration's line, its calls; a name declared on
    /// several lines of the file is written `name@line` for each, as LCOV
    /// joins `FNDA` to `FN` by name) and `FNF`/`FNH`, `DA` per line,
    /// `BRDA` per arm (`-` where its statement's line never ran), the
    /// `BRF`/`BRH` and `LF`/`LH` totals, `end_of_record`.
    pub fn lcov(&self, test_name: &str) -> String {
        let mut out = String::new();
        for (file, lines) in &self.lines {
            let _ = writeln!(out, "TN:{test_name}\nSF:{file}");
            let functions = self.functions.get(file);
            let written = |(line, name): &(u32, String)| match functions
                .into_iter()
                .flatten()
                .filter(|(k, _)| k.1 == *name)
                .count()
            {
                1 => name.clone(),
                _ => format!("{name}@{line}"),
            };
            for (key, _) in functions.into_iter().flatten() {
                let _ = writeln!(out, "FN:{},{}", key.0, written(key));
            }
            for (key, calls) in functions.into_iter().flatten() {
                let _ = writeln!(out, "FNDA:{calls},{}", written(key));
            }
            if let Some(f) = functions {
                let _ = writeln!(out, "FNF:{}\nFNH:{}", f.len(), f.values().filter(|&&v| v > 0).count());
            }
            let arms = self.arms.get(file);
            for (key, hits) in arms.into_iter().flatten() {
                let ran = lines.get(&key.0).is_some_and(|&h| h > 0);
                let taken = if ran { hits.to_string() } else { "-".into() };
                let _ = writeln!(out, "BRDA:{},{},{},{taken}", key.0, key.1, key.2);
            }
            let (bf, bh) = arms.map_or((0, 0), |a| (a.len(), a.values().filter(|&&v| v > 0).count()));
            let _ = writeln!(out, "BRF:{bf}\nBRH:{bh}");
            for (line, hits) in lines {
                let _ = writeln!(out, "DA:{line},{hits}");
            }
            let lh = lines.values().filter(|&&v| v > 0).count();
            let _ = writeln!(out, "LF:{}\nLH:{lh}\nend_of_record", lines.len());
        }
        out
    }
}
