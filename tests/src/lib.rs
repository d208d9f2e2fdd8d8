//! Hardware-in-the-loop tests live in `tests/`.
