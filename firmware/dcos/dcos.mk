DCOS_PORTABLE_SRCS := firmware/dcos/src/GregorianCalendar.cpp
