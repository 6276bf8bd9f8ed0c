#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| plm_fuzz::targets::rfc2217(data));
