//! The end of a child's stderr, for error messages: a thread drains the pipe continuously (so a
//! child that floods stderr never blocks on a full pipe) into a ring buffer of fixed capacity
//! (so a flood of any size takes [`STDERR_TAIL_BYTES`] of memory), and errors quote its last
//! whole lines (at most [`STDERR_TAIL_LINES`]).

use std::collections::VecDeque;
use std::io::Read;
use std::sync::{Arc, Mutex};
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

/// The most bytes of a child's stderr kept (the last ones, 2 KiB).
pub const STDERR_TAIL_BYTES: usize = 2048;

/// The most lines of a child's stderr quoted in an error (the last ones).
pub const STDERR_TAIL_LINES: usize = 20;

/// How long a quote waits for the drain to reach the end of the pipe (the child's last words,
/// written just before it died): bounded, since a grandchild outside the child's process group
/// may keep the pipe open.
const LAST_WORDS_WAIT: Duration = Duration::from_millis(200);

/// The last [`STDERR_TAIL_BYTES`] bytes written, in a ring buffer allocated once.
#[derive(Debug)]
pub struct Tail {
    bytes: VecDeque<u8>,
    /// Whether bytes were dropped from the front (the quote then starts at a whole line).
    cut: bool,
}

impl Default for Tail {
    fn default() -> Self {
        Self::new()
    }
}

impl Tail {
    /// An empty tail; its buffer is allocated now and never grows.
    pub fn new() -> Self {
        Self {
            bytes: VecDeque::with_capacity(STDERR_TAIL_BYTES),
            cut: false,
        }
    }

    /// Appends `chunk`, dropping the oldest bytes beyond [`STDERR_TAIL_BYTES`].
    pub fn push(&mut self, chunk: &[u8]) {
        let keep = &chunk[chunk.len().saturating_sub(STDERR_TAIL_BYTES)..];
        let excess = (self.bytes.len() + keep.len()).saturating_sub(STDERR_TAIL_BYTES);
        if excess > 0 || keep.len() < chunk.len() {
            self.cut = true;
        }
        self.bytes.drain(..excess);
        self.bytes.extend(keep);
    }

    /// The bytes kept.
    pub fn len(&self) -> usize {
        self.bytes.len()
    }

    /// Whether nothing was written.
    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// The bytes the ring buffer holds room for (allocated once: it does not grow).
    pub fn capacity(&self) -> usize {
        self.bytes.capacity()
    }

    /// The last [`STDERR_TAIL_LINES`] lines kept, as text (invalid UTF-8 replaced), trimmed;
    /// when the front was cut, the partial first line is left out (unless it is all there is).
    pub fn text(&self) -> String {
        let (a, b) = self.bytes.as_slices();
        let bytes = [a, b].concat();
        let text = String::from_utf8_lossy(&bytes);
        let mut text = text.trim();
        if self.cut {
            if let Some((_, rest)) = text.split_once('\n') {
                text = rest;
            }
        }
        let lines: Vec<&str> = text.lines().collect();
        lines[lines.len().saturating_sub(STDERR_TAIL_LINES)..]
            .join("\n")
            .trim()
            .to_string()
    }
}

/// A thread draining a child's stderr into a shared [`Tail`].
pub struct Drain {
    tail: Arc<Mutex<Tail>>,
    thread: Option<JoinHandle<()>>,
}

impl Drain {
    /// Starts draining `pipe` (until it closes, i.e. until every process holding it ended).
    pub fn start(pipe: impl Read + Send + 'static) -> Self {
        let tail = Arc::new(Mutex::new(Tail::new()));
        let shared = tail.clone();
        let thread = thread::Builder::new()
            .name("mfh-child-stderr".into())
            .spawn(move || drain(pipe, &shared))
            .ok();
        Self { tail, thread }
    }

    /// The quote of the tail for an error: "; its stderr ends: …", or empty. Waits (at most
    /// [`LAST_WORDS_WAIT`]) for the pipe to close, so that a dead child's last words are in.
    pub fn quote(&self) -> String {
        let deadline = Instant::now() + LAST_WORDS_WAIT;
        while self.thread.as_ref().is_some_and(|t| !t.is_finished()) && Instant::now() < deadline {
            thread::sleep(Duration::from_millis(5));
        }
        let text = self.tail.lock().map(|t| t.text()).unwrap_or_default();
        if text.is_empty() {
            String::new()
        } else {
            format!("; its stderr ends: {text}")
        }
    }
}

fn drain(mut pipe: impl Read, tail: &Mutex<Tail>) {
    let mut buf = [0u8; 8192];
    loop {
        match pipe.read(&mut buf) {
            Ok(0) => return,
            Ok(n) => {
                if let Ok(mut t) = tail.lock() {
                    t.push(&buf[..n]);
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(_) => return,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flood_keeps_the_capacity_and_quotes_whole_last_lines() {
        let mut tail = Tail::new();
        let capacity = tail.capacity();
        assert!((STDERR_TAIL_BYTES..=2 * STDERR_TAIL_BYTES).contains(&capacity));
        // 10 MB in chunks of every size, from 1 byte to more than the capacity.
        let mut written = 0usize;
        let mut i = 0usize;
        while written < 10_000_000 {
            let line = format!("line {i} of the flood\n");
            let chunk = line.repeat(1 + i % 300);
            tail.push(chunk.as_bytes());
            written += chunk.len();
            i += 1;
            assert!(tail.len() <= STDERR_TAIL_BYTES);
        }
        tail.push(b"the last line\n");
        assert_eq!(tail.len(), STDERR_TAIL_BYTES);
        assert_eq!(tail.capacity(), capacity, "the ring buffer grew");
        let text = tail.text();
        assert!(text.ends_with("the last line"), "{text}");
        assert!(text.lines().count() <= STDERR_TAIL_LINES);
        assert!(text
            .lines()
            .all(|l| l.starts_with("line ") || l == "the last line"));
    }

    #[test]
    fn a_short_stderr_is_quoted_whole() {
        let mut tail = Tail::new();
        assert_eq!(tail.text(), "");
        tail.push(b"Traceback\n  File x\nValueError: bad\n");
        assert_eq!(tail.text(), "Traceback\n  File x\nValueError: bad");
        // One line longer than the buffer: its end is all there is.
        let mut long = Tail::new();
        long.push(&[b'x'; 3 * STDERR_TAIL_BYTES]);
        assert_eq!(long.text().len(), STDERR_TAIL_BYTES);
    }

    #[test]
    fn the_drain_reads_to_the_end_and_quotes() {
        let data = b"a\nb\nmarker\n".repeat(100_000);
        let drain = Drain::start(std::io::Cursor::new(data));
        let quote = drain.quote();
        assert!(quote.starts_with("; its stderr ends: "), "{quote}");
        assert!(quote.ends_with("marker"), "{quote}");
    }
}
