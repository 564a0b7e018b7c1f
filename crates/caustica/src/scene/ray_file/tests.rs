//! Tests of the whole reader through `parse`.
