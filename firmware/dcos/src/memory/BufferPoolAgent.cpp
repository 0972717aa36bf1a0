// The buffer pool memory agent's interface object (seed 7.7): each primitive
// forwards to the kernel side, internal::BufferPoolManager.
#include <dcos/BufferPoolAgent.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/BufferPoolManager.hpp>
#include <dcos/internal/ConfigurationService.hpp>

namespace dcos {

using internal::BufferPoolManager;

DCOS_CONFIGURATION_SERVICE Result<ObjectId> BufferPoolAgent::Create(void* area, size_t areaBytes, size_t bufferSize, const char* name,
                                         Visibility visibility)
{
    return BufferPoolManager::Create(area, areaBytes, bufferSize, name, visibility);
}

DCOS_CONFIGURATION_SERVICE Status BufferPoolAgent::Delete(ObjectId pool) { return BufferPoolManager::Delete(pool); }

// Allocate and Return, with their fast paths, are in BufferPoolManager.cpp.

Result<BufferPoolStatistics> BufferPoolAgent::GetStatistics(ObjectId pool)
{
    return BufferPoolManager::GetStatistics(pool);
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> BufferPoolAgent::NameToObject(const char* name)
{
    return internal::orRemoteName(BufferPoolManager::NameToObject(name, Visibility::Local), ObjectType::BufferPool,
                                  name);
}

DCOS_CONFIGURATION_SERVICE Status BufferPoolAgent::AddObjects(size_t count) { return BufferPoolManager::AddObjects(count); }

DCOS_CONFIGURATION_SERVICE Status BufferPoolAgent::XferOwnership(ObjectId pool, ObjectId newOwner)
{
    return BufferPoolManager::XferOwnership(pool, newOwner);
}

DCOS_CONFIGURATION_SERVICE Status BufferPoolAgent::XferOwnership(ObjectId pool, void* buffer, ObjectId newOwner)
{
    return BufferPoolManager::XferOwnership(pool, buffer, newOwner);
}

} // namespace dcos
