//! FMI 2.0 export glue.
