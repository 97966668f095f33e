// expect syntax: 81_datetime_empty.pov:2:14: error: empty format string in datetime
#declare D = datetime(0, "");
