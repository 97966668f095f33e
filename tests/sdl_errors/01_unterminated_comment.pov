// expect syntax: 01_unterminated_comment.pov:3:1: error: unterminated comment
sphere { 0, 1 }
/* never closed
