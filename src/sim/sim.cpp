// Layer 3 (simulated board): physics and I/O models that implement the board seam.
// This translation unit only anchors the library; the models live beside it.
namespace motwin::sim {}
