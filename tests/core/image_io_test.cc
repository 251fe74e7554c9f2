// Tests of core/image_io.h (being written).
