# SPDX-License-Identifier: MIT
# Embed a text file as a C string: cmake -DIN=file -DOUT=header.h -DNAME=symbol -P embed.cmake
file(READ ${IN} hex HEX)
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
file(WRITE ${OUT} "// generated from ${IN} by cmake/embed.cmake: do not edit\nstatic const char ${NAME}[] = {${bytes}0x00};\n")
