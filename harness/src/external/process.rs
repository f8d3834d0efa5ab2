//! The child process: started with `sh -c` in a process group of its own, spoken to by JSON
//! lines (in the protocol version it chose at `describe`), read with a timeout; its group is
//! ended (SIGTERM, then SIGKILL) and it is reaped after an error and on drop.
//!
//! Reading stdout with a timeout needs a reader thread and a channel (std has no timed read on
//! a pipe); writing goes through a writer thread too, so that a child that stops reading its
//! stdin cannot block mfh on a full pipe, and stderr is drained by a third
//! ([`super::stderr_tail`]). The threads end when the child's pipes close, which ending its
//! group guarantees.

use super::group::{self, Group};
use super::protocol::{quote_non_finite, Answer, Description, Request, VERSIONS};
use super::stderr_tail::Drain;
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::thread;
use std::time::Duration;

/// The default per-request timeout (seconds): generous for a pure-Python batch of 65 536 items
/// (≈ 0.3 s measured), short enough that a hung child is reported within a CI step.
pub const DEFAULT_TIMEOUT_SECONDS: f64 = 10.0;

/// The longest answer line accepted (bytes, 64 MiB): the bound on an answer's size, and so on
/// the memory one answer takes (the line, then its decoded numbers, ≤ 3/4 of it in version 2).
/// A batch of 65 536 directions is ≈ 4 MB as version-1 text, 2.1 MB as version-2 base64.
pub const MAX_LINE_BYTES: u64 = 64 << 20;

/// What went wrong talking to the child; each names the request and what came back.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExternalError {
    /// The command could not be started.
    #[error("cannot start `{command}`: {reason}")]
    Spawn {
        /// The command.
        command: String,
        /// The OS error.
        reason: String,
    },
    /// No answer within the timeout.
    #[error(
        "request {request}: no answer within {seconds} s (the child's process group was \
         ended){stderr}"
    )]
    Timeout {
        /// The request (op, id, items).
        request: String,
        /// The timeout.
        seconds: f64,
        /// The tail of the child's stderr ("; its stderr ends: …", or empty).
        stderr: String,
    },
    /// The child exited (or closed stdout) before answering.
    #[error("request {request}: the child exited before answering ({status}){stderr}")]
    Exited {
        /// The request.
        request: String,
        /// The exit status.
        status: String,
        /// The tail of the child's stderr.
        stderr: String,
    },
    /// The answer is not the JSON object the protocol asks for.
    #[error("request {request}: malformed answer ({reason}){}", got_suffix(.got))]
    Malformed {
        /// The request.
        request: String,
        /// What is wrong.
        reason: String,
        /// The start of what came back (empty when the reason quotes it, or nothing came).
        got: String,
    },
    /// The child answered with its own error.
    #[error("request {request}: the child answered an error: {message}")]
    Child {
        /// The request.
        request: String,
        /// The child's message.
        message: String,
    },
    /// The answer has the wrong number of items.
    #[error("request {request}: asked for {asked} items, the answer has {got}")]
    WrongLength {
        /// The request.
        request: String,
        /// Items asked.
        asked: usize,
        /// Items answered.
        got: usize,
    },
    /// The answer contains NaN (not a protocol error: the audit goes on with the NaN, which
    /// the checks judge as a Rust model's; [`super::ExternalModel::nan_answers`] lists them).
    #[error("request {request}: the answer's {field:?} is NaN at item {index} (input {input})")]
    NotANumber {
        /// The request.
        request: String,
        /// The answer's array (`values`, `m`, `wo`, `pdf`, `weight`).
        field: String,
        /// The first NaN item.
        index: usize,
        /// The input of that item.
        input: String,
    },
    /// The child's description is not acceptable.
    #[error("describe: {0}")]
    Describe(String),
    /// An earlier error stopped the session.
    #[error("request {request}: not sent, the session failed earlier")]
    Stopped {
        /// The request.
        request: String,
    },
}

enum Line {
    Text(String),
    TooLong,
    Eof,
    Failed(String),
}

/// A running child speaking the protocol.
pub struct Session {
    command: String,
    child: Child,
    group: Group,
    to_child: Option<Sender<Vec<u8>>>,
    lines: Receiver<Line>,
    stderr: Drain,
    timeout: Duration,
    next_id: u64,
    failed: bool,
    version: u32,
}

impl Session {
    /// Starts `command` with `sh -c` in a process group of its own, its stdin and stdout piped,
    /// its stderr drained (the last lines are quoted in errors).
    pub fn start(command: &str, timeout: Duration) -> Result<Self, ExternalError> {
        let mut builder = Command::new("sh");
        builder.arg("-c").arg(command);
        group::own_group(&mut builder);
        let mut child = builder
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| ExternalError::Spawn {
                command: command.to_string(),
                reason: e.to_string(),
            })?;
        let mut group = Group::of(&child);
        let pipes = (child.stdin.take(), child.stdout.take(), child.stderr.take());
        let (Some(stdin), Some(stdout), Some(stderr_pipe)) = pipes else {
            group.end(&mut child);
            return Err(ExternalError::Spawn {
                command: command.to_string(),
                reason: "its standard streams were not piped".to_string(),
            });
        };
        let (tx_line, lines) = mpsc::channel();
        thread::spawn(move || read_lines(stdout, tx_line));
        let (to_child, rx_write) = mpsc::channel::<Vec<u8>>();
        thread::spawn(move || write_lines(stdin, rx_write));
        let stderr = Drain::start(stderr_pipe);
        Ok(Self {
            command: command.to_string(),
            child,
            group,
            to_child: Some(to_child),
            lines,
            stderr,
            timeout,
            next_id: 0,
            failed: false,
            version: 1,
        })
    }

    /// The protocol version spoken: 1 until `describe` has been answered, then the child's
    /// choice (when mfh speaks it).
    pub fn version(&self) -> u32 {
        self.version
    }

    /// The command the child was started with.
    pub fn command(&self) -> &str {
        &self.command
    }

    /// Sends `request` and returns its checked answer. After any error the child is killed and
    /// every later call fails with [`ExternalError::Stopped`].
    pub fn call(&mut self, request: &Request<'_>) -> Result<Answer, ExternalError> {
        self.call_line(request).map(|(answer, _)| answer)
    }

    /// The `describe` exchange: the child's description, parsed from its answer line. Later
    /// requests use the version it chose, if mfh speaks it ([`VERSIONS`]; otherwise
    /// [`Description::validate`] refuses it).
    pub fn describe(&mut self) -> Result<Description, ExternalError> {
        let (_, line) = self.call_line(&Request::Describe)?;
        let parsed = serde_json::from_str::<Description>(&quote_non_finite(line.trim()));
        let description = parsed.map_err(|e| {
            self.fail();
            ExternalError::Describe(format!(
                "the answer is not a description ({e}); got: {}",
                excerpt(&line)
            ))
        })?;
        if VERSIONS.contains(&description.protocol) {
            self.version = description.protocol;
        }
        Ok(description)
    }

    /// Marks the session failed (an answer was unusable) and kills the child.
    pub fn fail(&mut self) {
        self.failed = true;
        self.kill();
    }

    fn call_line(&mut self, request: &Request<'_>) -> Result<(Answer, String), ExternalError> {
        let id = self.next_id;
        self.next_id += 1;
        let label = format!("{} (id {id}, {} items)", request.op(), request.len());
        if self.failed {
            return Err(ExternalError::Stopped { request: label });
        }
        let result = self.exchange(request, id, &label);
        if result.is_err() {
            self.failed = true;
            self.kill();
        }
        result
    }

    fn exchange(
        &mut self,
        request: &Request<'_>,
        id: u64,
        label: &str,
    ) -> Result<(Answer, String), ExternalError> {
        let mut bytes = request.to_line(id, self.version).into_bytes();
        bytes.push(b'\n');
        let sent = self
            .to_child
            .as_ref()
            .is_some_and(|tx| tx.send(bytes).is_ok());
        if !sent {
            return Err(self.exited(label));
        }
        let line = match self.lines.recv_timeout(self.timeout) {
            Ok(Line::Text(t)) => t,
            Ok(Line::TooLong) => {
                return Err(ExternalError::Malformed {
                    request: label.to_string(),
                    reason: format!("an answer line longer than {MAX_LINE_BYTES} bytes"),
                    got: String::new(),
                })
            }
            Ok(Line::Failed(e)) => {
                return Err(ExternalError::Malformed {
                    request: label.to_string(),
                    reason: format!("stdout unreadable: {e}"),
                    got: String::new(),
                })
            }
            Ok(Line::Eof) | Err(RecvTimeoutError::Disconnected) => return Err(self.exited(label)),
            Err(RecvTimeoutError::Timeout) => {
                self.kill();
                return Err(ExternalError::Timeout {
                    request: label.to_string(),
                    seconds: self.timeout.as_secs_f64(),
                    stderr: self.stderr.quote(),
                });
            }
        };
        let malformed = |reason: String| ExternalError::Malformed {
            request: label.to_string(),
            reason,
            got: excerpt(&line),
        };
        // Version 1 may write Python's bare NaN / Infinity tokens; version 2's arrays are
        // base64 (in which "NaN" occurs by chance), so its lines are quoted only if they fail
        // to parse as they are (a version-2 answer may carry small JSON arrays).
        let parsed = if self.version < 2 {
            serde_json::from_str(&quote_non_finite(line.trim()))
        } else {
            serde_json::from_str(line.trim())
                .or_else(|_| serde_json::from_str(&quote_non_finite(line.trim())))
        };
        let answer: Answer =
            parsed.map_err(|e| malformed(format!("not a JSON answer object: {e}")))?;
        if answer.id != Some(id) {
            return Err(malformed(match answer.id {
                Some(got) => format!("the answer's id is {got}, expected {id}"),
                None => format!("the answer has no id, expected {id}"),
            }));
        }
        if let Some(message) = answer.error.clone() {
            return Err(ExternalError::Child {
                request: label.to_string(),
                message,
            });
        }
        Ok((answer, line))
    }

    fn exited(&mut self, label: &str) -> ExternalError {
        // The pipe closed: wait a moment for the exit status (bounded), then kill.
        let mut status = "still running, stdout closed".to_string();
        for _ in 0..50 {
            if let Ok(Some(s)) = self.child.try_wait() {
                status = s.to_string();
                break;
            }
            thread::sleep(Duration::from_millis(10));
        }
        self.kill();
        ExternalError::Exited {
            request: label.to_string(),
            status,
            stderr: self.stderr.quote(),
        }
    }

    /// Closes the child's stdin and ends its process group (what it started too); reaps it.
    fn kill(&mut self) {
        self.to_child = None;
        self.group.end(&mut self.child);
    }

    /// Asks the child to exit, waits up to the timeout (at most 2 s), then ends its process
    /// group (what it left running too); reaps it in any case.
    pub fn shutdown(&mut self) {
        if !self.failed {
            if let Some(tx) = &self.to_child {
                let mut line = Request::Shutdown
                    .to_line(self.next_id, self.version)
                    .into_bytes();
                line.push(b'\n');
                let _ = tx.send(line);
            }
        }
        self.to_child = None; // closes stdin once the writer drains
        let deadline = std::time::Instant::now() + self.timeout.min(Duration::from_secs(2));
        while std::time::Instant::now() < deadline {
            if let Ok(Some(_)) = self.child.try_wait() {
                break;
            }
            thread::sleep(Duration::from_millis(5));
        }
        self.kill();
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        self.kill();
    }
}

fn read_lines(stdout: impl Read, tx: Sender<Line>) {
    let mut reader = BufReader::with_capacity(1 << 16, stdout);
    loop {
        let mut buf = Vec::new();
        let read = reader
            .by_ref()
            .take(MAX_LINE_BYTES)
            .read_until(b'\n', &mut buf);
        let line = match read {
            Ok(0) => Line::Eof,
            Ok(_) if buf.last() != Some(&b'\n') && buf.len() as u64 >= MAX_LINE_BYTES => {
                Line::TooLong
            }
            // Valid UTF-8 (every well-formed answer) is taken without a copy.
            Ok(_) => Line::Text(
                String::from_utf8(buf)
                    .unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned()),
            ),
            Err(e) => Line::Failed(e.to_string()),
        };
        let stop = !matches!(line, Line::Text(_));
        if tx.send(line).is_err() || stop {
            return;
        }
    }
}

fn write_lines(mut stdin: ChildStdin, rx: Receiver<Vec<u8>>) {
    for bytes in rx {
        if stdin.write_all(&bytes).and_then(|_| stdin.flush()).is_err() {
            return;
        }
    }
}

/// "; got: …" after a malformed-answer message, unless there is nothing to show.
fn got_suffix(got: &str) -> String {
    if got.is_empty() {
        String::new()
    } else {
        format!("; got: {got}")
    }
}

/// The first 200 characters of `text`, for error messages.
pub fn excerpt(text: &str) -> String {
    let t = text.trim_end();
    match t.char_indices().nth(200) {
        Some((i, _)) => format!("{}… ({} bytes)", &t[..i], t.len()),
        None => t.to_string(),
    }
}
