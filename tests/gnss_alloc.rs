//! The GNSS stream decoder allocates nothing per chunk, frame or sentence: a counting global
//! allocator (tests/common/counting_alloc.rs) sees no allocation while a long mixed stream is
//! decoded, once the decoder exists.

use agsteer::input::nmea0183::{clock::Receipt, convert::StreamParams};
use agsteer::input::SourceId;
use agsteer::io::decoder::{DecoderParams, GnssDecoder, Protocol};
#[path = "common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::counted;

fn log(name: &str) -> Vec<u8> {
    std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tools/gnss/logs")
            .join(name),
    )
    .unwrap()
}

#[test]
fn decoding_allocates_nothing() {
    let streams = [
        (Protocol::Nmea0183, log("nmea-rtk.log")),
        (Protocol::Nmea0183, log("ublox-zed-f9p-nmea.log")),
        (Protocol::Ubx, log("ublox-zed-f9p-hp.log")),
        (Protocol::Ubx, log("ublox-f9p-rtcm.log")),
        (Protocol::Ubx, log("ublox-zed-f9t-ubx_nmea_l5.log")),
    ];
    for (protocol, data) in streams {
        let mut d = GnssDecoder::new(DecoderParams {
            protocol,
            stream: StreamParams {
                source: SourceId::Stream(0),
                baseline_angle: 0.0,
                max_delay_s: 0.5,
            },
            max_correction_age_s: 10.0,
        });
        let mut inputs = 0u64;
        let ((), allocations) = counted(|| {
            for (k, chunk) in data.chunks(61).enumerate() {
                d.push(
                    chunk,
                    &Receipt::at(k as f64 * 0.001),
                    &mut |_| inputs += 1,
                    &mut |_| {},
                );
            }
        });
        assert!(inputs > 5, "{protocol:?}: {:?}", d.counters());
        assert_eq!(allocations, 0, "{protocol:?}");
    }
}
