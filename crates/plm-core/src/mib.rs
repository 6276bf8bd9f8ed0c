//! Declarative MIB description (filled in with the ST7580 codec).
