//! `[gnss]`: where GNSS comes from — NMEA 2000 on the CAN bus, or a receiver speaking NMEA 0183
//! or UBX over a serial port, USB, UDP or TCP — and the NTRIP client that brings it RTK
//! corrections.
//!
//! Owns the section's keys, their defaults and their range checks, and builds the stream's and
//! the NTRIP client's parameter structs ([`GnssConfig::stream`], [`GnssConfig::ntrip`]).

use super::check::Checker;
use crate::input::nmea0183::convert::StreamParams;
use crate::input::SourceId;
use crate::io::decoder::{DecoderParams, Protocol};
use crate::io::ntrip::{NtripConfig, NtripVersion};
use crate::io::transport::{StreamConfig, Transport};
use serde::{Deserialize, Serialize};
use std::net::{IpAddr, SocketAddr};

/// Where positions come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum GnssSource {
    /// NMEA 2000 PGNs on the CAN bus.
    #[default]
    Can,
    /// NMEA 0183 sentences on the byte stream.
    Nmea0183,
    /// u-blox UBX on the byte stream.
    Ubx,
}

/// The byte stream's transport.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum TransportKind {
    /// A serial port or USB CDC-ACM device.
    #[default]
    Serial,
    Udp,
    Tcp,
}

/// Baud rates a GNSS receiver's UART offers.
pub const BAUD_RATES: [u32; 9] = [
    4800, 9600, 19_200, 38_400, 57_600, 115_200, 230_400, 460_800, 921_600,
];

/// `[gnss]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GnssConfig {
    /// "can", "nmea0183" or "ubx".
    pub source: GnssSource,
    /// "serial" (also USB CDC), "udp" or "tcp".
    pub transport: TransportKind,
    /// Serial device (a `/dev/serial/by-id/...` link survives replugging).
    pub device: String,
    /// Serial baud rate (8N1).
    pub baud: u32,
    /// UDP: local port and address to listen on.
    pub udp_port: u16,
    pub udp_bind: String,
    /// UDP: accept datagrams only from this address ("" = any).
    pub udp_source: String,
    /// UDP: send RTCM corrections to this "address:port" ("" = nowhere).
    pub udp_rtcm_to: String,
    /// A separate serial port for the RTCM corrections (a receiver's second UART), "" = the
    /// receiver's own port (or `udp_rtcm_to`).
    pub rtcm_device: String,
    /// Baud rate of `rtcm_device` (8N1).
    pub rtcm_baud: u32,
    /// TCP client: the receiver's (or bridge's) host and port.
    pub tcp_host: String,
    pub tcp_port: u16,
    /// Direction of a dual-antenna baseline (primary → secondary) relative to the vehicle's
    /// forward axis, degrees, counter-clockwise (−90: the secondary antenna on the right).
    pub baseline_angle_deg: f64,
    /// An epoch arriving later than this beyond the link's best is stale, s.
    pub max_delay_s: f64,
    /// No byte for this long reopens a serial or TCP stream, s.
    pub silence_timeout_s: f64,
    /// Reopen back-off, s.
    pub backoff_min_s: f64,
    pub backoff_max_s: f64,
    /// Bytes per second taken at most from the stream (flood protection).
    pub max_rate_bytes_s: f64,
    /// Use the host's UTC to measure latency (only with a disciplined clock: chrony/NTP).
    pub host_utc: bool,
    /// Corrections older than this (receiver's or NTRIP's) turn RTK fixed into float, s.
    pub max_correction_age_s: f64,
    /// NTRIP caster ("" = no NTRIP client).
    pub ntrip_host: String,
    pub ntrip_port: u16,
    pub ntrip_mountpoint: String,
    pub ntrip_user: String,
    /// The password, or "" with `ntrip_password_file`.
    #[serde(serialize_with = "redact")]
    pub ntrip_password: String,
    /// A file holding the password (readable only by the daemon's user).
    pub ntrip_password_file: String,
    /// NTRIP revision, 1 or 2.
    pub ntrip_version: u8,
    /// Position sent to the caster as GGA this often, s (0 = never).
    pub ntrip_gga_interval_s: f64,
    /// No data from the caster for this long: reconnect, s.
    pub ntrip_timeout_s: f64,
}

/// Passwords are never printed (`agsteer config` shows the resolved file).
fn redact<S: serde::Serializer>(v: &str, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(if v.is_empty() { "" } else { "(hidden)" })
}

impl Default for GnssConfig {
    fn default() -> Self {
        GnssConfig {
            source: GnssSource::Can,
            transport: TransportKind::Serial,
            device: "/dev/ttyACM0".into(),
            baud: 115_200,
            udp_port: 9999,
            udp_bind: "0.0.0.0".into(),
            udp_source: String::new(),
            udp_rtcm_to: String::new(),
            rtcm_device: String::new(),
            rtcm_baud: 115_200,
            tcp_host: String::new(),
            tcp_port: 0,
            baseline_angle_deg: 0.0,
            max_delay_s: 0.5,
            silence_timeout_s: 2.0,
            backoff_min_s: 0.2,
            backoff_max_s: 2.0,
            max_rate_bytes_s: 200_000.0,
            host_utc: true,
            max_correction_age_s: 10.0,
            ntrip_host: String::new(),
            ntrip_port: 2101,
            ntrip_mountpoint: String::new(),
            ntrip_user: String::new(),
            ntrip_password: String::new(),
            ntrip_password_file: String::new(),
            ntrip_version: 2,
            ntrip_gga_interval_s: 10.0,
            ntrip_timeout_s: 10.0,
        }
    }
}

impl GnssConfig {
    /// Whether GNSS comes from a byte stream.
    pub fn is_stream(&self) -> bool {
        self.source != GnssSource::Can
    }

    /// Checks of `[gnss]`: every key, whatever the source.
    pub(crate) fn validate(&self, c: &mut Checker) {
        let g = self;
        if !BAUD_RATES.contains(&g.baud) {
            c.push(
                "gnss.baud",
                g.baud.to_string(),
                "must be one of 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600",
            );
        }
        if !BAUD_RATES.contains(&g.rtcm_baud) {
            c.push(
                "gnss.rtcm_baud",
                g.rtcm_baud.to_string(),
                "must be one of 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600",
            );
        }
        if g.udp_bind.parse::<IpAddr>().is_err() {
            c.push(
                "gnss.udp_bind",
                format!("{:?}", g.udp_bind),
                "must be an IP address (\"0.0.0.0\": every interface)",
            );
        }
        if !g.udp_source.is_empty() && g.udp_source.parse::<IpAddr>().is_err() {
            c.push(
                "gnss.udp_source",
                format!("{:?}", g.udp_source),
                "must be an IP address or \"\" (any sender)",
            );
        }
        if !g.udp_rtcm_to.is_empty() && g.udp_rtcm_to.parse::<SocketAddr>().is_err() {
            c.push(
                "gnss.udp_rtcm_to",
                format!("{:?}", g.udp_rtcm_to),
                "must be \"address:port\" or \"\"",
            );
        }
        c.range(
            "gnss.baseline_angle_deg",
            g.baseline_angle_deg,
            -180.0,
            180.0,
        );
        c.range("gnss.max_delay_s", g.max_delay_s, 0.05, 5.0);
        c.range("gnss.silence_timeout_s", g.silence_timeout_s, 0.5, 60.0);
        c.range("gnss.backoff_min_s", g.backoff_min_s, 0.05, 10.0);
        c.range(
            "gnss.backoff_max_s",
            g.backoff_max_s,
            g.backoff_min_s.max(0.05),
            300.0,
        );
        c.range(
            "gnss.max_rate_bytes_s",
            g.max_rate_bytes_s,
            1_000.0,
            10_000_000.0,
        );
        c.range(
            "gnss.max_correction_age_s",
            g.max_correction_age_s,
            1.0,
            120.0,
        );
        if g.is_stream() {
            match g.transport {
                TransportKind::Serial if g.device.trim().is_empty() => {
                    c.push("gnss.device", format!("{:?}", g.device), "must name the receiver's device with transport = \"serial\"")
                }
                TransportKind::Udp if g.udp_port == 0 => {
                    c.push("gnss.udp_port", "0".into(), "must be a port in 1..=65535 with transport = \"udp\"")
                }
                TransportKind::Tcp if g.tcp_host.trim().is_empty() || g.tcp_port == 0 => c.push(
                    "gnss.tcp_host",
                    format!("{:?}:{}", g.tcp_host, g.tcp_port),
                    "tcp_host and tcp_port (1..=65535) must name the receiver's server with transport = \"tcp\"",
                ),
                _ => {}
            }
        }
        // NTRIP.
        if g.ntrip_version != 1 && g.ntrip_version != 2 {
            c.push(
                "gnss.ntrip_version",
                g.ntrip_version.to_string(),
                "must be 1 or 2",
            );
        }
        if g.ntrip_gga_interval_s != 0.0 {
            c.range(
                "gnss.ntrip_gga_interval_s",
                g.ntrip_gga_interval_s,
                1.0,
                600.0,
            );
        }
        c.range("gnss.ntrip_timeout_s", g.ntrip_timeout_s, 2.0, 120.0);
        if !g.ntrip_host.is_empty() {
            if !g.is_stream() {
                c.push(
                    "gnss.ntrip_host",
                    format!("{:?}", g.ntrip_host),
                    "an NTRIP client needs a receiver on a byte stream (gnss.source = \"nmea0183\" or \"ubx\") to send the corrections to",
                );
            }
            let m = g.ntrip_mountpoint.trim_start_matches('/');
            if m.is_empty() || m.contains(|ch: char| ch.is_whitespace() || ch.is_control()) {
                c.push(
                    "gnss.ntrip_mountpoint",
                    format!("{:?}", g.ntrip_mountpoint),
                    "must name the caster's mountpoint (no spaces)",
                );
            }
            if g.ntrip_port == 0 {
                c.push("gnss.ntrip_port", "0".into(), "must be in 1..=65535");
            }
            if !g.ntrip_password.is_empty() && !g.ntrip_password_file.is_empty() {
                c.push(
                    "gnss.ntrip_password_file",
                    format!("{:?}", g.ntrip_password_file),
                    "give the password or a password file, not both",
                );
            }
            if g.transport == TransportKind::Udp
                && g.udp_rtcm_to.is_empty()
                && g.rtcm_device.is_empty()
                && g.is_stream()
            {
                c.push(
                    "gnss.udp_rtcm_to",
                    "\"\"".into(),
                    "must say where the corrections go (the receiver's \"address:port\", or set gnss.rtcm_device) when NTRIP feeds a UDP receiver",
                );
            }
        }
    }

    /// The separate serial port for the corrections (device, baud), if one is configured.
    pub fn rtcm_serial(&self) -> Option<(std::path::PathBuf, u32)> {
        (!self.rtcm_device.is_empty()).then(|| (self.rtcm_device.clone().into(), self.rtcm_baud))
    }

    /// The byte stream's parameters, when GNSS comes from one.
    pub fn stream(&self) -> Option<StreamConfig> {
        let protocol = match self.source {
            GnssSource::Can => return None,
            GnssSource::Nmea0183 => Protocol::Nmea0183,
            GnssSource::Ubx => Protocol::Ubx,
        };
        let transport = match self.transport {
            TransportKind::Serial => Transport::Serial {
                device: self.device.clone().into(),
                baud: self.baud,
            },
            TransportKind::Udp => Transport::Udp {
                bind: SocketAddr::new(self.udp_bind.parse().ok()?, self.udp_port),
                source: self.udp_source.parse().ok(),
                rtcm_to: self.udp_rtcm_to.parse().ok(),
            },
            TransportKind::Tcp => Transport::Tcp {
                host: self.tcp_host.clone(),
                port: self.tcp_port,
            },
        };
        Some(StreamConfig {
            transport,
            decoder: DecoderParams {
                protocol,
                stream: StreamParams {
                    source: SourceId::Stream(0),
                    baseline_angle: self.baseline_angle_deg.to_radians(),
                    max_delay_s: self.max_delay_s,
                },
                max_correction_age_s: self.max_correction_age_s,
            },
            silence_timeout_s: self.silence_timeout_s,
            backoff_min_s: self.backoff_min_s,
            backoff_max_s: self.backoff_max_s,
            max_rate_bytes_s: self.max_rate_bytes_s,
            host_utc: self.host_utc,
        })
    }

    /// The NTRIP client's parameters, with `password` (from the key or the password file,
    /// read by the daemon), when a caster is configured.
    pub fn ntrip(&self, password: String) -> Option<NtripConfig> {
        if self.ntrip_host.is_empty() {
            return None;
        }
        Some(NtripConfig {
            host: self.ntrip_host.clone(),
            port: self.ntrip_port,
            mountpoint: self.ntrip_mountpoint.trim_start_matches('/').to_string(),
            user: self.ntrip_user.clone(),
            password,
            version: if self.ntrip_version == 1 {
                NtripVersion::V1
            } else {
                NtripVersion::V2
            },
            gga_interval_s: self.ntrip_gga_interval_s,
            timeout_s: self.ntrip_timeout_s,
            backoff_min_s: 1.0,
            backoff_max_s: 30.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problems(g: GnssConfig) -> Vec<String> {
        let mut c = Checker::default();
        g.validate(&mut c);
        c.problems.iter().map(|p| p.to_string()).collect()
    }

    #[test]
    fn defaults_are_valid_and_keys_are_named() {
        assert!(problems(GnssConfig::default()).is_empty());
        let bad = GnssConfig {
            baud: 12345,
            max_delay_s: f64::NAN,
            udp_source: "nobody".into(),
            ..GnssConfig::default()
        };
        let p = problems(bad);
        assert!(
            p.iter().any(|m| m.starts_with("gnss.baud = 12345")),
            "{p:?}"
        );
        assert!(
            p.iter().any(|m| m.starts_with("gnss.max_delay_s = NaN")),
            "{p:?}"
        );
        assert!(p.iter().any(|m| m.starts_with("gnss.udp_source")), "{p:?}");
        let tcp = GnssConfig {
            source: GnssSource::Nmea0183,
            transport: TransportKind::Tcp,
            ..GnssConfig::default()
        };
        assert!(problems(tcp).iter().any(|m| m.starts_with("gnss.tcp_host")));
        let ntrip = GnssConfig {
            source: GnssSource::Ubx,
            ntrip_host: "caster.example".into(),
            ntrip_password: "x".into(),
            ntrip_password_file: "/etc/agsteer/ntrip".into(),
            ..GnssConfig::default()
        };
        let p = problems(ntrip);
        assert!(
            p.iter().any(|m| m.starts_with("gnss.ntrip_mountpoint")),
            "{p:?}"
        );
        assert!(
            p.iter().any(|m| m.starts_with("gnss.ntrip_password_file")),
            "{p:?}"
        );
        let on_can = GnssConfig {
            ntrip_host: "caster.example".into(),
            ntrip_mountpoint: "M".into(),
            ..GnssConfig::default()
        };
        assert!(problems(on_can)
            .iter()
            .any(|m| m.starts_with("gnss.ntrip_host")));
    }

    #[test]
    fn stream_parameters() {
        let g = GnssConfig {
            source: GnssSource::Ubx,
            baseline_angle_deg: -90.0,
            ..GnssConfig::default()
        };
        let s = g.stream().unwrap();
        assert_eq!(s.decoder.protocol, Protocol::Ubx);
        assert!((s.decoder.stream.baseline_angle + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!(matches!(
            s.transport,
            Transport::Serial { baud: 115_200, .. }
        ));
        assert!(GnssConfig::default().stream().is_none());
        let printed = toml::to_string(&GnssConfig {
            ntrip_password: "hunter2".into(),
            ..g
        })
        .unwrap();
        assert!(!printed.contains("hunter2"), "{printed}");
    }
}
