//! Analyses on threads of their own, so that no document holds the server for longer than its
//! deadline (docs/editors.md): the server waits for an analysis until the deadline, and then
//! answers on without it while the analysis runs to its end in the background. A thread cannot
//! be stopped from outside, so a late analysis is left to finish, and the server takes its
//! result if the document has not changed meanwhile.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, TryRecvError};
use std::time::Instant;

use clay_dsl::Loader;
use clay_dsl::analysis::Analysis;

/// How long the server waits for an analysis, in milliseconds, unless told otherwise
/// (`--analysis-timeout-ms`).
pub const DEFAULT_TIMEOUT_MS: u64 = 5000;

/// What an analysis needs, owned, so that it can move to its thread.
pub struct Work {
    pub text: String,
    /// The path the text is compiled as.
    pub path: String,
    /// The analysis of the last text that parsed.
    pub previous: Option<Arc<Analysis>>,
    pub loader: Arc<dyn Loader + Send + Sync>,
}

/// An analysis under way.
pub struct Job {
    done: Receiver<Option<Analysis>>,
}

/// Where an analysis is.
pub enum State {
    Done(Box<Analysis>),
    /// It panicked (the panic message went to standard error), or no thread could be made.
    Failed,
    Running,
}

impl Job {
    /// Starts analysing on a new thread.
    pub fn start(work: Work) -> Self {
        let (tx, done) = mpsc::sync_channel(1);
        let run = move || {
            let fresh = catch_unwind(AssertUnwindSafe(|| {
                Analysis::with_loader(
                    &work.text,
                    &work.path,
                    work.previous.as_deref(),
                    &*work.loader,
                )
            }));
            // The server may have gone on without this analysis (the document closed).
            let _ = tx.send(fresh.ok());
        };
        // Without a thread the sender is gone, and waiting says `Failed`.
        let _ = std::thread::Builder::new()
            .name("lsp-analysis".into())
            .spawn(run);
        Self { done }
    }

    /// Waits for the analysis until `until` at most. Once it has said `Done` or `Failed`, the
    /// job is over.
    pub fn wait(&self, until: Instant) -> State {
        let got = self
            .done
            .recv_timeout(until.saturating_duration_since(Instant::now()));
        match got {
            Ok(Some(analysis)) => State::Done(Box::new(analysis)),
            Ok(None) | Err(RecvTimeoutError::Disconnected) => State::Failed,
            Err(RecvTimeoutError::Timeout) => State::Running,
        }
    }

    /// Where the analysis is now, without waiting.
    pub fn poll(&self) -> State {
        match self.done.try_recv() {
            Ok(Some(analysis)) => State::Done(Box::new(analysis)),
            Ok(None) | Err(TryRecvError::Disconnected) => State::Failed,
            Err(TryRecvError::Empty) => State::Running,
        }
    }
}
