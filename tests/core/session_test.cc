// Tests of core/session.h (being written).
