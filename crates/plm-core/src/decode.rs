//! Named-field view of stream elements (filled in with the ST7580 codec).
