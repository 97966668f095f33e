// expect syntax: 52_fopen_escape.pov:2:10: error: writing "../../../../../../tmp/partray_escape.txt" is not permitted: files may only be written in the scene's directory or the current directory
#fopen F "../../../../../../tmp/partray_escape.txt" write
