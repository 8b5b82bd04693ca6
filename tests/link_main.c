/* link_main.c - calls into the C object (implementation) and the C++ object (declarations). */
#include <stdio.h>
int link_a_triangles(void);
int link_b_result_is_named(void);
int main(void)
{
    int t = link_a_triangles(), named = link_b_result_is_named();
    printf("triangles %d, named %d\n", t, named);
    return (t == 32 && named) ? 0 : 1;
}
