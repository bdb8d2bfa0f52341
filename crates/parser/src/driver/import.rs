//! pbrt-v4's `Import`: the named file is parsed on a thread of its own
//! while the importing file's parse goes on (pbrt-v4 `parser.cpp`, the
//! `Import` case, and `BasicSceneBuilder::CopyForImport`/`MergeImported`).
//!
//! pbrt-v4 allows `Import` only in the world block; the imported file
//! starts from a copy of the importer's graphics state and what it changes
//! (transform, material, attributes) does not leak back, while what it
//! defines (shapes, lights, materials, textures, media, objects) joins the
//! scene. pbrt-v4 adds those definitions to the scene as its threads get
//! to them and merges the shapes at the end; here the imported file's
//! directives are recorded, and once parsing is done every import is
//! handed to the target at the place of its `Import`, between
//! `import_begin` and `import_end`, with the importing file's directives
//! around it in file order. The target sees exactly what a parse on one
//! thread would give it ([`ParseOptions::parallel_import`] `false`), so
//! entity order and the image do not depend on thread timing. Errors in an
//! imported file keep their `file:line:col`.

use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::thread::JoinHandle;

use super::record::Recorder;
use super::{Diagnostic, Diagnostics, FileLoc, ParseOptions, Run};

/// The parse of one imported file: its directives and its diagnostics.
type Parsed = (Recorder, Diagnostics);

/// A piece of the deferred directive stream.
pub(super) enum Segment {
    /// Directives of the importing file.
    Main(Recorder),
    /// An imported file, being parsed or parsed.
    Import { loc: FileLoc, job: Job },
}

/// An import's parse.
pub(super) enum Job {
    Thread(JoinHandle<Parsed>),
    Done(Box<Parsed>),
}

/// Import threads running now, across every parse in the process.
static IMPORT_THREADS: AtomicUsize = AtomicUsize::new(0);

/// One running import thread's slot; dropping it frees the slot. A file
/// with thousands of `Import`s parses them on at most
/// [`max_import_threads`] threads at once: once all are busy, an import is
/// parsed in place by the thread that reads it.
struct ImportThread;

impl ImportThread {
    /// Takes a slot if one is free.
    fn reserve() -> bool {
        let max = max_import_threads();
        IMPORT_THREADS
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |n| {
                (n < max).then_some(n + 1)
            })
            .is_ok()
    }
}

impl Drop for ImportThread {
    fn drop(&mut self) {
        IMPORT_THREADS.fetch_sub(1, Ordering::AcqRel);
    }
}

/// Import threads running now.
#[cfg(test)]
pub(super) fn import_threads_running() -> usize {
    IMPORT_THREADS.load(Ordering::Acquire)
}

/// The most import threads running at once: the machine's parallelism.
pub(super) fn max_import_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Parses the file at `path` into a recorder, with `ancestors` (the
/// importing files) for the cycle check.
fn parse_import(
    opts: ParseOptions,
    path: PathBuf,
    ancestors: Vec<PathBuf>,
    loc: FileLoc,
) -> Parsed {
    let mut rec = Recorder::default();
    let diags = {
        let mut run = Run::new(&opts, &mut rec);
        run.ancestors = ancestors;
        run.is_import = true;
        match run.open(&path, true) {
            Ok(src) => {
                run.push(src);
                run.run();
            }
            Err(msg) => run.report(Diagnostic::error(loc, format!("cannot read {msg}"))),
        }
        match run.finish() {
            Ok(d) | Err(d) => d,
        }
    };
    (rec, diags)
}

impl Run<'_> {
    /// Starts parsing the imported file at `path` (canonically `canon`),
    /// named by the `Import` at `loc`.
    pub(super) fn start_import(&mut self, path: PathBuf, canon: Option<PathBuf>, loc: &FileLoc) {
        // The directives read before this one were delivered or recorded
        // already; those after it are recorded until the end.
        let mut ancestors = self.ancestors.clone();
        ancestors.extend(self.stack.iter().filter_map(|s| s.canon.clone()));
        ancestors.extend(canon);
        let opts = self.opts.clone();
        let l = loc.clone();
        let job = if self.opts.parallel_import && ImportThread::reserve() {
            let spawned = std::thread::Builder::new()
                .name("rpbrt-import".into())
                .spawn({
                    let (opts, path, ancestors, l) =
                        (opts.clone(), path.clone(), ancestors.clone(), l.clone());
                    move || {
                        let _slot = ImportThread;
                        parse_import(opts, path, ancestors, l)
                    }
                });
            match spawned {
                Ok(h) => Job::Thread(h),
                // No thread to be had: parse it here.
                Err(_) => {
                    drop(ImportThread);
                    Job::Done(Box::new(parse_import(opts, path, ancestors, l)))
                }
            }
        } else {
            Job::Done(Box::new(parse_import(opts, path, ancestors, l)))
        };
        self.deferred.push(Segment::Import {
            loc: loc.clone(),
            job,
        });
        self.deferred.push(Segment::Main(Recorder::default()));
    }

    /// Hands the deferred imports and directives to the target, in order.
    pub(super) fn replay_deferred(&mut self) {
        for seg in std::mem::take(&mut self.deferred) {
            if self.stopped {
                return;
            }
            match seg {
                Segment::Main(rec) => self.replay(rec),
                Segment::Import { loc, job } => {
                    let parsed = match job {
                        Job::Done(p) => *p,
                        Job::Thread(h) => match h.join() {
                            Ok(p) => p,
                            Err(_) => {
                                self.report(Diagnostic::error(
                                    loc,
                                    "internal error: the thread parsing this Import failed",
                                ));
                                continue;
                            }
                        },
                    };
                    self.deliver_import(loc, parsed);
                }
            }
        }
    }

    fn deliver_import(&mut self, loc: FileLoc, (rec, diags): Parsed) {
        // Whether the target reports anything in these files is known
        // only after the replay below.
        self.held.extend(diags.sources.into_files());
        for d in diags.items {
            self.report(d);
        }
        if let Some(open) = rec.open.last() {
            self.report(Diagnostic::error(
                open.clone(),
                "missing end to this block in an Imported file (an Import may not change \
                 the graphics state of the file that imports it)",
            ));
            return;
        }
        let r = self.target.import_begin(loc.clone());
        let failed = r.is_err();
        self.drain(r);
        if failed {
            return;
        }
        self.replay(rec);
        let r = self.target.import_end(loc);
        self.drain(r);
    }

    fn replay(&mut self, rec: Recorder) {
        for c in rec.items {
            let r = c.replay(&mut *self.target);
            self.drain(r);
        }
    }
}
