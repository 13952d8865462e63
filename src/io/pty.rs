//! A pseudo-terminal standing in for a serial GNSS receiver: whatever is written to its
//! master side arrives on its slave device (`/dev/pts/N`), which agsteerd opens as it would
//! `/dev/ttyACM0`. The simulator speaks NMEA 0183 or UBX through one; the tests unplug a
//! "receiver" by dropping it and plug one back by making a new one behind the same link.

use std::ffi::CStr;
use std::fs::File;
use std::io;
use std::os::fd::{AsRawFd, FromRawFd};
use std::path::{Path, PathBuf};

/// The master side of a pseudo-terminal and the path of its slave device.
pub struct Pty {
    master: File,
    slave: PathBuf,
}

fn check(r: libc::c_int) -> io::Result<libc::c_int> {
    if r < 0 {
        Err(io::Error::last_os_error())
    } else {
        Ok(r)
    }
}

impl Pty {
    /// A new pseudo-terminal in raw mode (no echo, no line editing, 8 bits): bytes pass
    /// through untouched, as on a serial line.
    pub fn open() -> io::Result<Pty> {
        // SAFETY: plain libc calls on a descriptor this function owns; the buffer given to
        // ptsname_r is ours and its length is passed.
        unsafe {
            let fd = check(libc::posix_openpt(
                libc::O_RDWR | libc::O_NOCTTY | libc::O_CLOEXEC,
            ))?;
            let master = File::from_raw_fd(fd);
            check(libc::grantpt(fd))?;
            check(libc::unlockpt(fd))?;
            let mut name = [0 as libc::c_char; 128];
            let r = libc::ptsname_r(fd, name.as_mut_ptr(), name.len());
            if r != 0 {
                return Err(io::Error::from_raw_os_error(r));
            }
            let slave = PathBuf::from(CStr::from_ptr(name.as_ptr()).to_string_lossy().into_owned());
            // Raw mode is set through the slave; it stays while the master lives.
            let s = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .custom_flags_noctty()
                .open(&slave)?;
            let mut t: libc::termios = std::mem::zeroed();
            check(libc::tcgetattr(s.as_raw_fd(), &mut t))?;
            libc::cfmakeraw(&mut t);
            check(libc::tcsetattr(s.as_raw_fd(), libc::TCSANOW, &t))?;
            Ok(Pty { master, slave })
        }
    }

    /// The device to open (`/dev/pts/N`).
    pub fn path(&self) -> &Path {
        &self.slave
    }

    /// The master side: write the receiver's bytes here.
    pub fn master(&self) -> &File {
        &self.master
    }

    /// Make writes to the master non-blocking (a full buffer returns `WouldBlock` instead of
    /// waiting for the reader).
    pub fn set_nonblocking(&self) -> io::Result<()> {
        let fd = self.master.as_raw_fd();
        // SAFETY: fcntl on a descriptor we own.
        unsafe {
            let flags = check(libc::fcntl(fd, libc::F_GETFL))?;
            check(libc::fcntl(fd, libc::F_SETFL, flags | libc::O_NONBLOCK))?;
        }
        Ok(())
    }
}

trait NoCtty {
    fn custom_flags_noctty(&mut self) -> &mut Self;
}

impl NoCtty for std::fs::OpenOptions {
    fn custom_flags_noctty(&mut self) -> &mut Self {
        use std::os::unix::fs::OpenOptionsExt;
        self.custom_flags(libc::O_NOCTTY)
    }
}
