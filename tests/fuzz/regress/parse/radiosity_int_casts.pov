// Out-of-range numbers where the parser keeps an int: each must be an
// error or a clamp, never an undefined float-to-int conversion.
#declare Big = 1e300 * 1e300;
global_settings { radiosity { recursion_limit Big count Big, Big nearest_count -Big } }
camera { location <0,0,-3> look_at 0 aperture 0.1 blur_samples 4, Big focal_point 0 }
text { internal Big "a" 1, 0 }
#declare F = function { internal(Big) }
