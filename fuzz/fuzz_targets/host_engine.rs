#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| plm_fuzz::targets::host_engine(data));
