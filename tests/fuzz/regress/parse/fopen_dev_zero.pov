// #fopen of a device for reading must fail at once (was read forever)
#fopen F "/dev/zero" read
#read (F, V)
