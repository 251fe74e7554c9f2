// Tests of core/sample_file.h (being written).
