// expect syntax: 06_unterminated_block.pov:4:1: error: unterminated union block opened at 2:7
union {
  sphere { 0, 1 }
