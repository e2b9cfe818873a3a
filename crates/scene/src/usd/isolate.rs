//! A stage is first read in a forked child process, so that a file that
//! makes the USD reader abort (an allocation the size of a corrupt count:
//! Rust aborts on a failed allocation, which no `catch_unwind` catches) or
//! hang fails with an error naming the file instead of taking the caller
//! with it. The child has an address-space limit and the parent a
//! deadline; only a file the child read whole is read again in-process.
//! Without `fork` (not Unix) the read runs in-process directly.

/// The most address space the trial read may add to what the process
/// already has mapped.
#[cfg(unix)]
const TRIAL_BYTES: u64 = 8 << 30;
/// How long the trial read may take.
#[cfg(unix)]
const TRIAL_SECONDS: u64 = 120;
/// The longest failure message passed back (well under a pipe's buffer).
#[cfg(unix)]
const MESSAGE_BYTES: usize = 8192;

/// `Ok` when `read` returned (whatever it returned) in a child process;
/// `Err` with what went wrong when the child crashed or ran out of time.
#[cfg(unix)]
pub fn trial(
    read: impl FnOnce() -> std::result::Result<(), String>,
) -> std::result::Result<(), String> {
    use std::time::{Duration, Instant};

    let mut fds = [0i32; 2];
    // SAFETY: `fds` is a valid two-int array for pipe(2).
    if unsafe { libc::pipe(fds.as_mut_ptr()) } != 0 {
        return Ok(()); // No pipe: read in-process, unguarded.
    }
    let (rx, tx) = (fds[0], fds[1]);
    // SAFETY: fork(2); the child only reads the file, writes to the pipe
    // and leaves with _exit, running no destructors of the parent's state.
    let pid = unsafe { libc::fork() };
    if pid < 0 {
        close(rx);
        close(tx);
        return Ok(());
    }
    if pid == 0 {
        close(rx);
        limit_memory();
        quiet();
        let message = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(read)) {
            Ok(_) => String::new(),
            Err(_) => "the USD reader panicked".to_string(),
        };
        let bytes = &message.as_bytes()[..message.len().min(MESSAGE_BYTES)];
        // SAFETY: writing a valid buffer to our end of the pipe, then _exit.
        unsafe {
            libc::write(tx, bytes.as_ptr().cast(), bytes.len());
            libc::_exit(0);
        }
    }
    close(tx);
    let deadline = Instant::now() + Duration::from_secs(TRIAL_SECONDS);
    let mut status = 0i32;
    let result = loop {
        // SAFETY: waiting on our own child.
        let done = unsafe { libc::waitpid(pid, &mut status, libc::WNOHANG) };
        if done == pid {
            break if libc::WIFEXITED(status) {
                Ok(())
            } else if libc::WIFSIGNALED(status) {
                Err(format!(
                    "the USD reader crashed reading it (signal {}; a corrupt size or count?)",
                    libc::WTERMSIG(status)
                ))
            } else {
                Err("the USD reader stopped abnormally".to_string())
            };
        }
        if done < 0 {
            break Ok(());
        }
        if Instant::now() > deadline {
            // SAFETY: killing and reaping our own child.
            unsafe {
                libc::kill(pid, libc::SIGKILL);
                libc::waitpid(pid, &mut status, 0);
            }
            break Err(format!(
                "the USD reader took over {TRIAL_SECONDS} s reading it"
            ));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let mut buf = vec![0u8; MESSAGE_BYTES];
    // SAFETY: reading into a buffer of the given length.
    let n = unsafe { libc::read(rx, buf.as_mut_ptr().cast(), buf.len()) };
    close(rx);
    let message = String::from_utf8_lossy(&buf[..n.max(0) as usize]).into_owned();
    match result {
        Ok(()) if !message.is_empty() => Err(message),
        other => other,
    }
}

#[cfg(not(unix))]
pub fn trial(
    read: impl FnOnce() -> std::result::Result<(), String>,
) -> std::result::Result<(), String> {
    let _ = read;
    Ok(())
}

#[cfg(unix)]
fn close(fd: i32) {
    // SAFETY: closing a descriptor this module opened.
    unsafe {
        libc::close(fd);
    }
}

/// Silences the child: its failure is the parent's to report, and a
/// backtrace of an abort (`RUST_BACKTRACE`) costs seconds to symbolise.
#[cfg(unix)]
fn quiet() {
    // SAFETY: the forked child has one thread; fd 2 is redirected to a
    // descriptor it opens.
    unsafe {
        std::env::set_var("RUST_BACKTRACE", "0");
        let null = libc::open(c"/dev/null".as_ptr(), libc::O_WRONLY);
        if null >= 0 {
            libc::dup2(null, 2);
            libc::close(null);
        }
    }
}

/// Caps the child's address space at what it has mapped plus
/// [`TRIAL_BYTES`], so a huge allocation fails in it.
#[cfg(unix)]
fn limit_memory() {
    // /proc/self/statm: the first field is the mapped size in pages.
    let pages = std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<u64>().ok());
    let Some(pages) = pages else { return };
    let mapped = pages * 4096;
    let bytes = mapped + TRIAL_BYTES;
    let limit = libc::rlimit {
        rlim_cur: bytes as libc::rlim_t,
        rlim_max: bytes as libc::rlim_t,
    };
    // SAFETY: setting a resource limit of this (child) process.
    unsafe {
        libc::setrlimit(libc::RLIMIT_AS, &limit);
    }
}
