// The few C++ ABI hooks a freestanding, exception-free kernel still needs.
#include <stddef.h>

extern "C" [[noreturn]] void dcosPanic(const char* format, ...);

extern "C" {

// Called through a vtable slot of an abstract class; only a corrupted object
// or a call during construction can get here.
void __cxa_pure_virtual()
{
    dcosPanic("pure virtual function called");
}

// Static objects of a controller live until power-off, so their destructors
// are never registered, let alone run.
int __cxa_atexit(void (*)(void*), void*, void*)
{
    return 0;
}

void* __dso_handle = nullptr;

} // extern "C"

// A virtual destructor makes the compiler emit a deleting destructor that
// refers to operator delete, even though DCOS never deletes from a heap. Any
// call is a bug, so it stops the node loudly.
void operator delete(void*) noexcept
{
    dcosPanic("operator delete called: the kernel has no heap");
}

void operator delete(void*, size_t) noexcept
{
    dcosPanic("operator delete called: the kernel has no heap");
}
