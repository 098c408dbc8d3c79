//! Evaluation against ground truth (issue #4 §4).
