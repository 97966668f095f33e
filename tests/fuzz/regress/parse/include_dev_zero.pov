// An include of a device must fail at once, not read forever or block.
#include "/dev/zero"
