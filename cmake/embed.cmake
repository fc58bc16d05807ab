# embed.cmake — a text file as a C string at build time: cmake -DIN=file -DOUT=header.h -DNAME=sym -P embed.cmake
# writes `static const unsigned char NAME[] = {0x.., ..., 0};` (bytes, so no escaping of quotes or backslashes).
file(READ "${IN}" hex HEX)
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
string(REPLACE "0x0a," "0x0a,\n" bytes "${bytes}") # one line of C per line of the file
file(WRITE "${OUT}.tmp" "/* generated from ${IN} by cmake/embed.cmake: do not edit */\nstatic const unsigned char ${NAME}[] = {\n${bytes}0};\n")
file(COPY_FILE "${OUT}.tmp" "${OUT}" ONLY_IF_DIFFERENT)
