#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| plm_fuzz::targets::pole_list(data));
