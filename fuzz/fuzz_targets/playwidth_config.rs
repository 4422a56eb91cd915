#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| moreau::fuzzing::playwidth_config(data));
