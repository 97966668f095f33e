// expect syntax: 02_unterminated_string.pov:2:14: error: unterminated string
#declare S = "abc
