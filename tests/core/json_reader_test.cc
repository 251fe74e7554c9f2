// Tests of core/json_reader.h (being written).
