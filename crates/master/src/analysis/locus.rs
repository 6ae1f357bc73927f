//! Root locus of the linear bogie (being written).
