// Tests of core/file_util.h (being written).
