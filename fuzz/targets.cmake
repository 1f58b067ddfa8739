# The fuzz targets (fuzz/TARGET.cpp, each defining LLVMFuzzerTestOneInput) and the product
# libraries each one exercises, nothing more. Read by fuzz/CMakeLists.txt (libFuzzer binaries,
# GYROD_FUZZ=ON) and tests/CMakeLists.txt (replay of the corpus and the regressions as tests).
set(GYROD_FUZZ_TARGETS recording_csv import_imucal config model_toml request)
set(GYROD_FUZZ_LIBS_recording_csv gyrod_formats)
set(GYROD_FUZZ_LIBS_import_imucal gyrod_formats)
set(GYROD_FUZZ_LIBS_config gyrod_daemon_config)
set(GYROD_FUZZ_LIBS_model_toml gyrod_formats)
set(GYROD_FUZZ_LIBS_request gyrod_protocol)
