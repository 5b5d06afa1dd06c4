//! FMI 3.0 layer.
