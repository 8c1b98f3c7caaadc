//! Conforming refinement by newest-vertex bisection (being written; see issue 3).
