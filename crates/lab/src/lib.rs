//! histencil-lab
