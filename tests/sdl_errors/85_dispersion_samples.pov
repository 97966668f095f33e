// expect syntax: 85_dispersion_samples.pov:4:37: error: dispersion_samples must be between 2 and 100000 (got 1)
// POV-Ray 3.7 stops with "Dispersion samples minimum is 2."
sphere { 0, 1 pigment { rgbf 1 }
  interior { ior 1.5 dispersion 1.1 dispersion_samples 1 } }
