// Compiled against an installed copy of sphere by the install_consumer test.
#include <sphere/dem.cuh>

#include <iostream>

int main()
{
    const sphere::vec3<double> v{1, 2, 3};
    std::cout << "sphere consumer: " << v.x << ' ' << v.y << ' ' << v.z << '\n';
    return 0;
}
