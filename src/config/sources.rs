//! `[sources]`: which GNSS source each input is taken from (issue 16 point 3).
//!
//! A real bus carries several receivers and heading sources at once; the node locks each input
//! — position, course/speed, heading, fix quality — on one of them (see
//! [`crate::input::source`]). Each is `"auto"` (the first suitable source, kept until stale), a
//! CAN source address (`"0x1C"` or `"28"`), an ISO 11783-5 NAME (`"name:A00082001C40FFFF"`,
//! 16 hex digits: the node at whatever address it claimed), or `"stream"` (the byte-stream
//! receiver of `[gnss]`).

use super::check::Checker;
use crate::input::source::{Choice, MagneticHeading, SourceParams};
use crate::input::{FixQuality, SourceId};
use serde::{Deserialize, Serialize};

/// `[sources]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SourcesConfig {
    pub position: String,
    pub course_speed: String,
    pub heading: String,
    /// "auto" follows the position's source.
    pub quality: String,
    /// A locked source that sent nothing of its kind for this long is dropped, s.
    pub stale_s: f64,
    /// "any", "rtk_float" or "rtk_fixed": the fix a source must report before automatic
    /// selection takes its positions.
    pub min_quality: String,
    /// "refuse" or "apply_variation".
    pub magnetic_heading: String,
    /// A change of source disengages the steering.
    pub disengage_on_change: bool,
}

impl Default for SourcesConfig {
    fn default() -> Self {
        SourcesConfig {
            position: "auto".into(),
            course_speed: "auto".into(),
            heading: "auto".into(),
            quality: "auto".into(),
            stale_s: 1.0,
            min_quality: "any".into(),
            magnetic_heading: "refuse".into(),
            disengage_on_change: true,
        }
    }
}

const CHOICE_RULE: &str = "must be \"auto\", a CAN source address 0..=253 (\"0x1C\" or \"28\"), \"name:\" and a 16-hex-digit ISO 11783-5 NAME, or \"stream\"";

/// A choice as written in the file.
pub fn parse_choice(text: &str) -> Option<Choice> {
    let t = text.trim();
    if t.eq_ignore_ascii_case("auto") {
        return Some(Choice::Auto);
    }
    if t.eq_ignore_ascii_case("stream") {
        return Some(Choice::Source(SourceId::Stream(0)));
    }
    if let Some(hex) = t.strip_prefix("name:").or_else(|| t.strip_prefix("NAME:")) {
        let hex = hex.trim();
        return (hex.len() == 16 && hex.bytes().all(|b| b.is_ascii_hexdigit()))
            .then(|| u64::from_str_radix(hex, 16).ok())
            .flatten()
            .map(Choice::Name);
    }
    let address = match t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        Some(hex) if !hex.is_empty() && hex.bytes().all(|b| b.is_ascii_hexdigit()) => {
            u8::from_str_radix(hex, 16).ok()
        }
        Some(_) => None,
        None if !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit()) => t.parse::<u8>().ok(),
        None => None,
    }?;
    (address <= 253).then_some(Choice::Source(SourceId::Can(address)))
}

fn parse_quality(text: &str) -> Option<FixQuality> {
    match text {
        "any" => Some(FixQuality::Other),
        "rtk_float" => Some(FixQuality::RtkFloat),
        "rtk_fixed" => Some(FixQuality::RtkFixed),
        _ => None,
    }
}

fn parse_magnetic(text: &str) -> Option<MagneticHeading> {
    match text {
        "refuse" => Some(MagneticHeading::Refuse),
        "apply_variation" => Some(MagneticHeading::ApplyVariation),
        _ => None,
    }
}

impl SourcesConfig {
    pub(crate) fn validate(&self, c: &mut Checker) {
        for (key, v) in [
            ("sources.position", &self.position),
            ("sources.course_speed", &self.course_speed),
            ("sources.heading", &self.heading),
            ("sources.quality", &self.quality),
        ] {
            if parse_choice(v).is_none() {
                c.push(key, format!("{v:?}"), CHOICE_RULE);
            }
        }
        c.range("sources.stale_s", self.stale_s, 0.1, 10.0);
        if parse_quality(&self.min_quality).is_none() {
            c.push(
                "sources.min_quality",
                format!("{:?}", self.min_quality),
                "must be \"any\", \"rtk_float\" or \"rtk_fixed\"",
            );
        }
        if parse_magnetic(&self.magnetic_heading).is_none() {
            c.push(
                "sources.magnetic_heading",
                format!("{:?}", self.magnetic_heading),
                "must be \"refuse\" or \"apply_variation\"",
            );
        }
    }

    /// The selector's parameters (a validated configuration; anything unreadable is "auto").
    pub fn params(&self) -> SourceParams {
        let choice = |s: &str| parse_choice(s).unwrap_or_default();
        SourceParams {
            position: choice(&self.position),
            course_speed: choice(&self.course_speed),
            heading: choice(&self.heading),
            quality: choice(&self.quality),
            stale_s: self.stale_s,
            min_quality: parse_quality(&self.min_quality).unwrap_or(FixQuality::Other),
            magnetic: parse_magnetic(&self.magnetic_heading).unwrap_or_default(),
            disengage_on_change: self.disengage_on_change,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choices_as_written() {
        assert_eq!(parse_choice("auto"), Some(Choice::Auto));
        assert_eq!(
            parse_choice("0x1C"),
            Some(Choice::Source(SourceId::Can(0x1C)))
        );
        assert_eq!(parse_choice("28"), Some(Choice::Source(SourceId::Can(28))));
        assert_eq!(
            parse_choice("stream"),
            Some(Choice::Source(SourceId::Stream(0)))
        );
        assert_eq!(
            parse_choice("name:A00082001C40FFFF"),
            Some(Choice::Name(0xA000_8200_1C40_FFFF))
        );
        for bad in [
            "",
            "254",
            "0x1FF",
            "-1",
            "name:A0008200",
            "name:+00082001C40FFFF",
            "can",
        ] {
            assert_eq!(parse_choice(bad), None, "{bad}");
        }
    }

    #[test]
    fn every_bad_key_is_named() {
        let cfg = SourcesConfig {
            position: "0x100".into(),
            heading: "name:xyz".into(),
            stale_s: f64::NAN,
            min_quality: "dgps".into(),
            magnetic_heading: "use".into(),
            ..Default::default()
        };
        let mut c = Checker::default();
        cfg.validate(&mut c);
        let keys: Vec<&str> = c.problems.iter().map(|p| p.key.as_str()).collect();
        assert_eq!(
            keys,
            [
                "sources.position",
                "sources.heading",
                "sources.stale_s",
                "sources.min_quality",
                "sources.magnetic_heading"
            ]
        );
        assert_eq!(SourcesConfig::default().params(), SourceParams::default());
    }
}
