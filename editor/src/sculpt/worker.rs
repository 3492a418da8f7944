//! One long-lived thread that runs the sculpt's background solver frames
//! ([`super::Sculpt::step_in_background`]): a request goes in on one channel, its result comes
//! back on another, one at a time. Starting an OS thread for every frame cost a spawn and a
//! join per UI frame; this thread is started once, at the first background frame, and ends
//! when its [`Worker`] is dropped (with the sculpt).

use std::sync::mpsc::{self, Receiver, Sender, TryRecvError};
use std::thread::JoinHandle;

/// The thread and its two channels. At most one request is out at a time.
pub(super) struct Worker<In, Out> {
    /// Requests to the thread (taken when dropped, which ends the thread's loop).
    requests: Option<Sender<In>>,
    /// Results from the thread: the work's value, or the message of its panic.
    results: Option<Receiver<Result<Out, String>>>,
    thread: Option<JoinHandle<()>>,
    /// A request is out and its result not yet taken.
    busy: bool,
}

impl<In: Send + 'static, Out: Send + 'static> Worker<In, Out> {
    /// Starts the thread, `name`d, which runs `work` on each request in turn. A panic in
    /// `work` is caught (as [`crate::guard::catching`] does) and handed back as its message;
    /// the thread goes on serving.
    pub(super) fn start(
        name: &str,
        mut work: impl FnMut(In) -> Out + Send + 'static,
    ) -> std::io::Result<Self> {
        let (requests, inbox) = mpsc::channel::<In>();
        let (outbox, results) = mpsc::channel();
        let thread = std::thread::Builder::new()
            .name(name.to_string())
            .spawn(move || {
                // blocks while idle; ends when the worker is dropped
                for request in inbox {
                    let result = crate::guard::catching(|| work(request));
                    // the worker was dropped while this ran: the result is freed here
                    if outbox.send(result).is_err() {
                        return;
                    }
                }
            })?;
        Ok(Self {
            requests: Some(requests),
            results: Some(results),
            thread: Some(thread),
            busy: false,
        })
    }

    /// Whether a request is out (running, or finished and not yet taken).
    pub(super) fn busy(&self) -> bool {
        self.busy
    }

    /// Hands `request` to the thread. Call only when not [`Worker::busy`]. Gives `request`
    /// back when the thread is gone.
    pub(super) fn submit(&mut self, request: In) -> Result<(), In> {
        debug_assert!(!self.busy, "one request at a time");
        let sender = self.requests.as_ref().expect("taken only when dropped");
        sender.send(request).map_err(|e| e.0)?;
        self.busy = true;
        Ok(())
    }

    /// The result of the request that is out: waiting for it when `wait`, else only if it
    /// is ready. `None` when no request is out, or (not waiting) it is still running.
    /// `Some(Err)` when the work panicked (its message) or the thread is gone.
    pub(super) fn take(&mut self, wait: bool) -> Option<Result<Out, String>> {
        if !self.busy {
            return None;
        }
        let results = self.results.as_ref().expect("taken only when dropped");
        let result = if wait {
            results.recv().map_err(|_| ())
        } else {
            match results.try_recv() {
                Err(TryRecvError::Empty) => return None,
                other => other.map_err(|_| ()),
            }
        };
        self.busy = false;
        Some(result.unwrap_or_else(|()| Err("the solver's thread is gone".to_string())))
    }
}

impl<In, Out> Drop for Worker<In, Out> {
    /// Ends the thread: a request still running finishes (its result is dropped on the
    /// thread, not here), then the thread's loop sees the closed channel and returns.
    fn drop(&mut self) {
        drop(self.results.take());
        drop(self.requests.take());
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::time::Duration;

    #[test]
    fn one_thread_serves_every_request_and_survives_a_panic() {
        let mut w = Worker::start("test-worker", |n: u32| {
            assert!(n != 13, "unlucky");
            (n * 2, std::thread::current().id())
        })
        .unwrap();
        assert_eq!(w.take(true), None, "nothing is out");
        let mut threads = Vec::new();
        for n in 0..10 {
            w.submit(n).unwrap();
            assert!(w.busy());
            let (twice, thread) = w.take(true).unwrap().unwrap();
            assert_eq!(twice, 2 * n);
            threads.push(thread);
            assert!(!w.busy());
        }
        assert!(threads.iter().all(|t| *t == threads[0]), "one thread");
        assert_ne!(threads[0], std::thread::current().id());
        w.submit(13).unwrap();
        assert_eq!(w.take(true), Some(Err("unlucky".to_string())));
        w.submit(4).unwrap();
        assert_eq!(w.take(true).unwrap().unwrap().0, 8, "it still serves");
    }

    #[test]
    fn not_waiting_takes_a_result_only_once_it_is_ready() {
        let (go, gate) = mpsc::channel::<()>();
        let gate = std::sync::Mutex::new(gate);
        let mut w = Worker::start("test-worker", move |n: u32| {
            gate.lock().unwrap().recv().unwrap();
            n + 1
        })
        .unwrap();
        w.submit(1).unwrap();
        std::thread::sleep(Duration::from_millis(20));
        assert_eq!(w.take(false), None, "still running");
        assert!(w.busy());
        go.send(()).unwrap();
        let got = loop {
            if let Some(r) = w.take(false) {
                break r;
            }
            std::thread::sleep(Duration::from_millis(1));
        };
        assert_eq!(got, Ok(2));
    }

    #[test]
    fn dropping_the_worker_ends_its_thread_after_the_running_request() {
        /// Counts its drops.
        struct Counted(Arc<AtomicUsize>);
        impl Drop for Counted {
            fn drop(&mut self) {
                self.0.fetch_add(1, Ordering::SeqCst);
            }
        }
        let drops = Arc::new(AtomicUsize::new(0));
        let counted = drops.clone();
        let mut w = Worker::start("test-worker", move |()| {
            std::thread::sleep(Duration::from_millis(50));
            Counted(counted.clone())
        })
        .unwrap();
        w.submit(()).unwrap();
        drop(w);
        // the running request finished and its result was freed; the thread ended, and with
        // it the work's own copy of the counter
        assert_eq!(drops.load(Ordering::SeqCst), 1);
        assert_eq!(Arc::strong_count(&drops), 1);
    }
}
