/* The C side of the Python package's bit-for-bit tests: problems also solved through the
 * binding, run here through the C API alone, their results written as raw doubles. */
#include <fcm/fcm.h>

#include <stdio.h>

int main(void)
{
  return 0;
}
