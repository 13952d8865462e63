#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| agsteer_fuzz::entries::status_reply(data));
