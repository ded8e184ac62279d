//! FMU placeholder
