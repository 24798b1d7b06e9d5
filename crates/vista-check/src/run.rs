//! The one run loop: cases (or mutants) checked by `jobs` workers, each
//! handed to a [`Reporter`] in order as soon as it and every earlier one
//! are done, then what the run leaves written ([`Run`]). `vista check`,
//! `--matrix`, `watch` and `mutate` run through it; the harness, whose
//! loop is libtest's, checks each trial with the same [`Checker::check`]
//! and ends with the same [`Run::finish`].

use std::path::PathBuf;

use vista_golden::{Case, GoldenError};
use vista_report::RunSummary;

use crate::SharedRun;
use crate::checker::{Checker, Filed, interrupted};
use crate::files::{Results, finish};

/// What a run shows as it goes. Every method has a default that shows
/// nothing, so a reporter says only what its command prints.
pub trait Reporter {
    /// The next case, checked and filed, in case order.
    fn case(&mut self, _filed: &Filed) {}
    /// The next mutant judged (`done` of `total`), in plan order.
    fn mutant(&mut self, _done: usize, _total: usize, _report: &vista_mutate::MutantReport) {}
}

/// A closure given each case is a reporter of cases.
impl<F: FnMut(&Filed)> Reporter for F {
    fn case(&mut self, filed: &Filed) {
        self(filed)
    }
}

/// One check run: its cases checked by `checker`, then its report.
pub struct Run<'a> {
    /// Checks and files each case.
    pub checker: Checker<'a>,
    /// The run as its report describes it (command, backend, adapter,
    /// partition); [`Run::run`] adds the interrupt line.
    pub summary: RunSummary,
    /// What is written beside the report.
    pub results: Results,
    /// A run shared by processes (cargo-nextest's): [`Run::finish`] records
    /// this process's cases and rebuilds the report from all the run's,
    /// every case id of the suite given.
    pub shared: Option<(SharedRun, Vec<String>)>,
}

/// What a run did: its cases in order and its report's index page.
pub struct Ran {
    /// Every case that finished, in case order.
    pub filed: Vec<Filed>,
    /// The report's `index.html`.
    pub index: PathBuf,
}

impl Run<'_> {
    /// Checks and files every case of `picked` with [`Checker::jobs`]
    /// workers, handing each to `reporter` in case order. Stops starting
    /// cases once [`interrupted`]: what finished before the interrupt is
    /// returned and reported; a case in flight then (its worker killed by
    /// the same Ctrl-C) is left out, not failed.
    pub fn check(&self, picked: &[&Case], jobs: usize, reporter: &mut dyn Reporter) -> Vec<Filed> {
        let jobs = self.checker.jobs(jobs, picked.len());
        // Cores the jobs leave idle go to each case's FLIP and report images.
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        vista_image::set_case_threads(cores / jobs);
        let mut out = Vec::with_capacity(picked.len());
        // The device serialises the workers' GPU runs while the others plan,
        // judge and write their report folder.
        in_order(
            picked,
            jobs,
            |case| (!interrupted()).then(|| self.checker.check(case)),
            |_, filed| {
                if let Some(filed) = filed.filter(|_| !interrupted()) {
                    reporter.case(&filed);
                    out.push(filed);
                }
            },
        );
        out
    }

    /// Writes what the run leaves for `filed` (see [`finish`], or
    /// [`SharedRun::finish`] for a shared run); returns the index page.
    pub fn finish(&self, filed: &[Filed]) -> Result<PathBuf, GoldenError> {
        match &self.shared {
            Some((shared, suite)) => shared.finish(&self.summary, filed, &self.results, suite),
            None => finish(self.checker.report_dir, &self.summary, filed, &self.results),
        }
    }

    /// [`Run::check`] then [`Run::finish`]; an interrupted run's summary
    /// says how many cases of how many finished.
    pub fn run(&mut self, picked: &[&Case], jobs: usize, reporter: &mut dyn Reporter) -> Result<Ran, GoldenError> {
        let filed = self.check(picked, jobs, reporter);
        self.note_interrupt(filed.len(), picked.len());
        let index = self.finish(&filed)?;
        Ok(Ran { filed, index })
    }

    /// Once [`interrupted`], the summary says how many of the `picked`
    /// cases finished (`filed`) before the Ctrl-C.
    pub fn note_interrupt(&mut self, filed: usize, picked: usize) {
        if interrupted() {
            self.summary.stopped = Some(format!(
                "Interrupted (Ctrl-C) after {filed} of {picked} cases: this report holds the cases that finished."
            ));
        }
    }
}

/// Judges every mutant of `planned` with `jobs` workers (see
/// [`vista_mutate::Judge`]), handing each report to `reporter` in plan
/// order; returns them in that order.
pub fn mutants(
    judge: &vista_mutate::Judge,
    planned: &[vista_mutate::Planned],
    jobs: usize,
    reporter: &mut dyn Reporter,
) -> Vec<vista_mutate::MutantReport> {
    let mut out = Vec::with_capacity(planned.len());
    in_order(
        planned,
        jobs,
        |p| judge.judge(p),
        |i, r| {
            reporter.mutant(i + 1, planned.len(), &r);
            out.push(r);
        },
    );
    out
}

/// Runs `work` on every item with `jobs` threads (at least one, at most
/// one per item), which take the items in order, and hands each result to
/// `take` on the calling thread in item order, as soon as it and every
/// earlier one are done.
///
/// Written here rather than on rayon, already a dependency: rayon's
/// ordered `collect` hands nothing back until every item is done, and its
/// unordered `for_each` runs `take` on the pool's threads out of order;
/// a check prints each case, and stops on Ctrl-C, as the cases finish.
pub fn in_order<T: Sync, R: Send>(
    items: &[T],
    jobs: usize,
    work: impl Fn(&T) -> R + Sync,
    mut take: impl FnMut(usize, R),
) {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, items.len().max(1)) {
            let (tx, next, work) = (tx.clone(), &next, &work);
            scope.spawn(move || {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(item) = items.get(i) else { break };
                    // The receiver is gone only if `take` panicked.
                    if tx.send((i, work(item))).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        let mut waiting = std::collections::BTreeMap::new();
        let mut taken = 0;
        for (i, r) in rx {
            waiting.insert(i, r);
            while let Some(r) = waiting.remove(&taken) {
                take(taken, r);
                taken += 1;
            }
        }
    });
}
