//! kd-tree
