//! `[isobus]`: agsteer as an ISO 11783 node — its NAME and address claim (ISO 11783-5, the
//! preferred address is `bus.source_address`) and the steering ECU it commands (ISO 11783-7).
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::Checker;
use crate::can::address_claim::ClaimParams;
use crate::can::isobus::{Name, NameFields};
use serde::{Deserialize, Serialize};

/// `[isobus]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IsobusConfig {
    /// Claim an address before sending anything else (ISO 11783-5).
    pub address_claim: bool,
    /// Addresses a self-configurable NAME may move to, inclusive.
    pub address_range: [u8; 2],
    /// NAME: may take another address from `address_range` when the preferred one is lost.
    pub self_configurable: bool,
    /// NAME: industry group (0..=7; 2 agricultural and forestry).
    pub industry_group: u8,
    /// NAME: device class (0..=127; 0 non-specific system).
    pub device_class: u8,
    /// NAME: device class instance (0..=15).
    pub device_class_instance: u8,
    /// NAME: function (0..=255; 23 vehicle navigation).
    pub function: u8,
    /// NAME: function instance (0..=31).
    pub function_instance: u8,
    /// NAME: ECU instance (0..=7).
    pub ecu_instance: u8,
    /// NAME: manufacturer code assigned by SAE (0..=2047).
    pub manufacturer_code: u16,
    /// NAME: identity number, unique per device (0..=2097151).
    pub identity_number: u32,
    /// Destination of the Guidance System Command: the steering ECU's address (0..=253), or
    /// 255 = the device whose claimed NAME has `steering_function`.
    pub steering_address: u8,
    /// NAME function of the steering ECU looked for when `steering_address` = 255 (16
    /// steering control; 134 tractor ECU).
    pub steering_function: u8,
    /// With `bus.output = "curvature"`: Guidance Machine Info older than this disengages, s
    /// (0.1..=2).
    pub machine_info_timeout_s: f64,
}

impl Default for IsobusConfig {
    fn default() -> Self {
        const NAME: NameFields = NameFields::GUIDANCE_CONTROLLER;
        IsobusConfig {
            address_claim: true,
            address_range: [128, 235],
            self_configurable: NAME.self_configurable,
            industry_group: NAME.industry_group,
            device_class: NAME.device_class,
            device_class_instance: NAME.device_class_instance,
            function: NAME.function,
            function_instance: NAME.function_instance,
            ecu_instance: NAME.ecu_instance,
            manufacturer_code: NAME.manufacturer_code,
            identity_number: NAME.identity_number,
            steering_address: 255,
            steering_function: 16,
            machine_info_timeout_s: 0.3,
        }
    }
}

impl IsobusConfig {
    /// The NAME the keys define.
    pub fn name(&self) -> Name {
        Name::new(&NameFields {
            self_configurable: self.self_configurable,
            industry_group: self.industry_group,
            device_class_instance: self.device_class_instance,
            device_class: self.device_class,
            function: self.function,
            function_instance: self.function_instance,
            ecu_instance: self.ecu_instance,
            manufacturer_code: self.manufacturer_code,
            identity_number: self.identity_number,
        })
    }

    /// The address claimer's parameters (`None` when `address_claim` is off).
    pub fn claim_params(&self, preferred: u8) -> Option<ClaimParams> {
        self.address_claim.then(|| ClaimParams {
            name: self.name(),
            preferred,
            range: (self.address_range[0], self.address_range[1]),
        })
    }

    /// Range checks of `[isobus]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        let mut int = |key: &str, v: u64, max: u64| {
            if v > max {
                c.push(key, v.to_string(), &format!("must be in 0..={max}"));
            }
        };
        int(
            "isobus.industry_group",
            self.industry_group as u64,
            NameFields::MAX_INDUSTRY_GROUP as u64,
        );
        int(
            "isobus.device_class",
            self.device_class as u64,
            NameFields::MAX_DEVICE_CLASS as u64,
        );
        int(
            "isobus.device_class_instance",
            self.device_class_instance as u64,
            NameFields::MAX_DEVICE_CLASS_INSTANCE as u64,
        );
        int(
            "isobus.function_instance",
            self.function_instance as u64,
            NameFields::MAX_FUNCTION_INSTANCE as u64,
        );
        int(
            "isobus.ecu_instance",
            self.ecu_instance as u64,
            NameFields::MAX_ECU_INSTANCE as u64,
        );
        int(
            "isobus.manufacturer_code",
            self.manufacturer_code as u64,
            NameFields::MAX_MANUFACTURER_CODE as u64,
        );
        int(
            "isobus.identity_number",
            self.identity_number as u64,
            NameFields::MAX_IDENTITY_NUMBER as u64,
        );
        let [lo, hi] = self.address_range;
        if lo > hi || hi > 253 {
            c.push(
                "isobus.address_range",
                format!("[{lo}, {hi}]"),
                "must be [first, last] with first <= last <= 253",
            );
        }
        if self.steering_address == 254 {
            c.push(
                "isobus.steering_address",
                "254".into(),
                "must be an address in 0..=253, or 255 to find the steering ECU by its NAME function",
            );
        }
        c.range(
            "isobus.machine_info_timeout_s",
            self.machine_info_timeout_s,
            0.1,
            2.0,
        );
    }
}
