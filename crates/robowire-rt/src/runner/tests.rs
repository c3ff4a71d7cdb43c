//! The runner with and without descriptors to wait on. Far deadlines are watchdogs: a job that
//! reaches one records it, and the test fails on that record, never on a measured duration.

use std::io::ErrorKind;
use std::os::fd::OwnedFd;
use std::os::unix::net::UnixDatagram;
use std::time::Duration;

use robowire_core::schedule::{Periodic, Time};

use super::{Job, Runner, RunnerOptions};
use crate::now;

/// How long a test waits for what should happen at once.
const WATCHDOG: Duration = Duration::from_secs(30);

fn pair() -> (UnixDatagram, UnixDatagram) {
    let (test, job) = UnixDatagram::pair().expect("a socket pair");
    job.set_nonblocking(true).expect("non-blocking");
    test.set_read_timeout(Some(WATCHDOG)).expect("a read timeout");
    (test, job)
}

fn fd(socket: &UnixDatagram) -> OwnedFd {
    socket.try_clone().expect("a second handle").into()
}

/// Echoes every datagram at once; ends on a 0.
struct Echo {
    socket: UnixDatagram,
    watchdog: Time,
    done: bool,
    at_deadline: bool,
}

impl Job for Echo {
    fn next_run(&mut self) -> Option<Time> {
        (!self.done).then_some(self.watchdog)
    }

    fn run(&mut self, now: Time) {
        let mut byte = [0u8; 1];
        loop {
            match self.socket.recv(&mut byte) {
                Ok(_) if byte[0] == 0 => self.done = true,
                Ok(_) => {
                    let _ = self.socket.send(&byte);
                }
                Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                Err(e) => panic!("receiving: {e}"),
            }
        }
        if now >= self.watchdog {
            (self.at_deadline, self.done) = (true, true);
        }
    }
}

#[test]
fn a_datagram_runs_the_job_at_once_on_its_thread() {
    let (test, job) = pair();
    let echo = Echo { watchdog: now() + WATCHDOG, socket: job, done: false, at_deadline: false };
    let fds = vec![fd(&echo.socket)];
    let runner = Runner::spawn_polling(RunnerOptions::named("echo"), echo, fds).unwrap();
    let mut byte = [0u8; 1];
    for i in 1..=100u8 {
        test.send(&[i]).unwrap();
        test.recv(&mut byte).expect("the echo (the job did not run on the datagram)");
        assert_eq!(byte[0], i);
    }
    test.send(&[0]).unwrap();
    let echo = runner.join().expect("the job");
    assert!(echo.done && !echo.at_deadline, "the job ended on the 0, before its deadline");
}

/// Reads one datagram per run; ends after `want`.
struct OneByOne {
    socket: UnixDatagram,
    watchdog: Time,
    want: usize,
    read: Vec<u8>,
    runs: usize,
    at_deadline: bool,
}

impl Job for OneByOne {
    fn next_run(&mut self) -> Option<Time> {
        (self.read.len() < self.want && !self.at_deadline).then_some(self.watchdog)
    }

    fn run(&mut self, now: Time) {
        self.runs += 1;
        let mut byte = [0u8; 1];
        if self.socket.recv(&mut byte).is_ok() {
            self.read.push(byte[0]);
        }
        self.at_deadline = now >= self.watchdog;
    }
}

#[test]
fn what_the_job_leaves_unread_runs_it_again() {
    let (test, job) = pair();
    for i in 1..=3u8 {
        test.send(&[i]).unwrap();
    }
    let reader =
        OneByOne { watchdog: now() + WATCHDOG, socket: job, want: 3, read: Vec::new(), runs: 0, at_deadline: false };
    let fds = vec![fd(&reader.socket)];
    let reader = Runner::spawn_polling(RunnerOptions::named("one-by-one"), reader, fds).unwrap().join().unwrap();
    assert_eq!(reader.read, [1, 2, 3]);
    assert!(!reader.at_deadline, "each datagram ran the job, not its deadline");
}

/// Runs once, and records whether that was before its deadline.
struct Once {
    deadline: Time,
    ran_at: Option<Time>,
}

impl Job for Once {
    fn next_run(&mut self) -> Option<Time> {
        self.ran_at.is_none().then_some(self.deadline)
    }

    fn run(&mut self, now: Time) {
        self.ran_at = Some(now);
    }
}

#[test]
fn a_waker_ends_the_poll() {
    let (_test, job) = pair();
    let once = Once { deadline: now() + WATCHDOG, ran_at: None };
    let deadline = once.deadline;
    let runner = Runner::spawn_polling(RunnerOptions::named("woken"), once, vec![fd(&job)]).unwrap();
    runner.waker().wake();
    let once = runner.join().unwrap();
    assert!(once.ran_at.is_some_and(|t| t < deadline), "the wake ran the job before its deadline");
}

#[test]
fn stop_ends_the_poll_without_running_the_job() {
    let (_test, job) = pair();
    let once = Once { deadline: now() + WATCHDOG, ran_at: None };
    let deadline = once.deadline;
    let once = Runner::spawn_polling(RunnerOptions::named("stopped"), once, vec![fd(&job)]).unwrap().stop().unwrap();
    assert_eq!(once.ran_at, None);
    assert!(now() < deadline, "stop ended the wait, not the deadline");
}

/// Ten ticks at 1 kHz, then done.
struct Ten {
    grid: Periodic,
    ticks: usize,
}

impl Job for Ten {
    fn next_run(&mut self) -> Option<Time> {
        (self.ticks < 10).then(|| self.grid.deadline())
    }

    fn run(&mut self, now: Time) {
        self.ticks += usize::from(self.grid.poll(now).is_some());
    }
}

#[test]
fn deadlines_hold_while_polling() {
    let (_test, job) = pair();
    let ten = Ten { grid: Periodic::new(now(), Duration::from_millis(1)), ticks: 0 };
    let ten = Runner::spawn_polling(RunnerOptions::named("ten"), ten, vec![fd(&job)]).unwrap().join().unwrap();
    assert_eq!(ten.ticks, 10);
}

#[test]
fn a_waker_runs_a_parked_job() {
    let once = Once { deadline: now() + WATCHDOG, ran_at: None };
    let deadline = once.deadline;
    let runner = Runner::spawn(RunnerOptions::named("parked"), once).unwrap();
    runner.waker().wake();
    let once = runner.join().unwrap();
    assert!(once.ran_at.is_some_and(|t| t < deadline), "the wake ran the job before its deadline");
}
