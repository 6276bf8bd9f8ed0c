//! ST7580 commands and MIB (UM0932 3.3, 4).
