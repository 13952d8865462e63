//! A serial or USB CDC-ACM device (a tty) read without ever blocking the runtime's thread.
//!
//! A tty's received bytes reach its reader through a kernel worker: the driver (a UART, the
//! USB CDC-ACM driver, a pseudo-terminal's master) queues them in the tty's flip buffer, and a
//! work item at normal priority (`flush_to_ldisc`) hands them to the line discipline, which
//! wakes readers. A read(2) or poll(2) that finds the line discipline empty first *waits for
//! that work item* (`n_tty_read` and `n_tty_poll` call `tty_buffer_flush_work`), even on a
//! non-blocking descriptor. The usual async read loop (read until `EWOULDBLOCK`, as
//! `tokio-serial` does) issues exactly such a read after every chunk, and on the daemon's
//! single thread it stalls the control loop until the worker runs: at once on an idle machine,
//! but a worker at normal priority waits behind every real-time thread (the daemon itself,
//! on one core) and behind a loaded CPU (traced at up to 0.57 s on a 2-core host beside
//! `stress-ng --cpu 2`).
//!
//! So this reader never reads an empty tty: it waits for the line discipline's wake-up
//! (epoll, read interest only), reads once, and takes a short read as "drained" (the next
//! bytes bring a new wake-up) — the rule tokio applies to sockets itself. The descriptor is
//! registered for reading only, so no write-side wake-up makes epoll poll the tty either.
//! Writes (RTCM corrections back to the receiver) are plain non-blocking writes, retried
//! after a short sleep when the tty's output buffer is full.

use std::future::Future;
use std::io;
use std::os::fd::{AsRawFd, FromRawFd, IntoRawFd, OwnedFd};
use std::path::Path;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{ready, Context, Poll};
use std::time::Duration;
use tokio::io::unix::AsyncFd;
use tokio::io::{AsyncRead, AsyncWrite, Interest, ReadBuf};

/// A full output buffer is tried again after this long.
const WRITE_RETRY: Duration = Duration::from_millis(2);

/// Open `device` at `baud`, 8N1, no flow control, raw, its input buffer flushed (bytes queued
/// before the open are old): the reading and the writing half.
pub fn open(device: &Path, baud: u32) -> io::Result<(TtyReader, TtyWriter)> {
    use tokio_serial::SerialPort;
    let path = device.to_string_lossy();
    let port = tokio_serial::new(path.as_ref(), baud)
        .data_bits(tokio_serial::DataBits::Eight)
        .parity(tokio_serial::Parity::None)
        .stop_bits(tokio_serial::StopBits::One)
        .flow_control(tokio_serial::FlowControl::None)
        .open_native()
        .map_err(io::Error::other)?;
    port.clear(tokio_serial::ClearBuffer::Input)
        .map_err(io::Error::other)?;
    // SAFETY: the descriptor was just taken from the port, which no longer owns it.
    let fd = unsafe { OwnedFd::from_raw_fd(port.into_raw_fd()) };
    configure(&fd)?;
    // SAFETY: an OwnedFd stays open, the same descriptor, until the AsyncFd drops it.
    let fd = unsafe { AsyncFd::register_with_interest(fd, Interest::READABLE) }
        .map_err(|e| e.into_parts().1)?;
    let fd = Arc::new(fd);
    Ok((TtyReader { fd: fd.clone() }, TtyWriter { fd, retry: None }))
}

fn check(r: libc::c_int) -> io::Result<libc::c_int> {
    if r < 0 {
        Err(io::Error::last_os_error())
    } else {
        Ok(r)
    }
}

/// Non-blocking, and a read returns as soon as one byte is there (VMIN 1, VTIME 0; another
/// program may have left VMIN 0, with which a read of an empty tty returns 0, end of file).
fn configure(fd: &OwnedFd) -> io::Result<()> {
    let raw = fd.as_raw_fd();
    // SAFETY: fcntl and termios calls on a descriptor we own; `t` is ours.
    unsafe {
        let flags = check(libc::fcntl(raw, libc::F_GETFL))?;
        check(libc::fcntl(raw, libc::F_SETFL, flags | libc::O_NONBLOCK))?;
        let mut t: libc::termios = std::mem::zeroed();
        check(libc::tcgetattr(raw, &mut t))?;
        t.c_cc[libc::VMIN] = 1;
        t.c_cc[libc::VTIME] = 0;
        check(libc::tcsetattr(raw, libc::TCSANOW, &t))?;
    }
    Ok(())
}

/// The reading half (see the module doc).
pub struct TtyReader {
    fd: Arc<AsyncFd<OwnedFd>>,
}

impl AsyncRead for TtyReader {
    fn poll_read(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        loop {
            let mut guard = ready!(self.fd.poll_read_ready(cx))?;
            let unfilled = buf.initialize_unfilled();
            let want = unfilled.len();
            let read = guard.try_io(|fd| {
                // SAFETY: reads at most `want` bytes into the buffer borrowed for it.
                let n = unsafe { libc::read(fd.as_raw_fd(), unfilled.as_mut_ptr().cast(), want) };
                usize::try_from(n).map_err(|_| io::Error::last_os_error())
            });
            match read {
                Ok(Ok(n)) => {
                    if n < want {
                        // Drained: wait for the next wake-up rather than read it empty.
                        guard.clear_ready();
                    }
                    buf.advance(n);
                    return Poll::Ready(Ok(()));
                }
                Ok(Err(e)) => return Poll::Ready(Err(e)),
                // Not ready after all (readiness cleared): wait again.
                Err(_) => continue,
            }
        }
    }
}

/// The writing half (see the module doc).
pub struct TtyWriter {
    fd: Arc<AsyncFd<OwnedFd>>,
    retry: Option<Pin<Box<tokio::time::Sleep>>>,
}

impl AsyncWrite for TtyWriter {
    fn poll_write(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        data: &[u8],
    ) -> Poll<io::Result<usize>> {
        loop {
            if let Some(sleep) = self.retry.as_mut() {
                ready!(sleep.as_mut().poll(cx));
                self.retry = None;
            }
            let raw = self.fd.get_ref().as_raw_fd();
            // SAFETY: writes at most `data.len()` bytes from the slice given.
            let n = unsafe { libc::write(raw, data.as_ptr().cast(), data.len()) };
            match usize::try_from(n) {
                Ok(n) => return Poll::Ready(Ok(n)),
                Err(_) => {
                    let e = io::Error::last_os_error();
                    if e.kind() != io::ErrorKind::WouldBlock {
                        return Poll::Ready(Err(e));
                    }
                    self.retry = Some(Box::pin(tokio::time::sleep(WRITE_RETRY)));
                }
            }
        }
    }

    fn poll_flush(self: Pin<&mut Self>, _cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Poll::Ready(Ok(()))
    }

    fn poll_shutdown(self: Pin<&mut Self>, _cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Poll::Ready(Ok(()))
    }
}
