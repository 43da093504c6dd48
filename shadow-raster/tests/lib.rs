//! Integration tests of shadow-raster.
