#include "core/scene.h"
#include <iostream>
int main(){ std::cout << surge::sceneKeysMarkdown(); }
