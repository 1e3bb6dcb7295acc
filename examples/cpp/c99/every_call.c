/* Every function of histencil.h, called from C99 as an engine's C code would call it, each
 * with what it must refuse without a device: null handles and pointers, a wrong struct size, a
 * handle of the wrong kind; and the calls that need none. Built by this folder's CMake with
 * -std=c99 -pedantic -Wall -Wextra -Werror against the installed static library (the proof that
 * the header is C); exit 0 when every call returned its code and said why. */
#include "histencil.h"

#include <stdio.h>
#include <string.h>

static int failures = 0;
static int calls = 0;

static void expect_ok(HistencilResult got, const char *what) {
    calls += 1;
    if (got != HISTENCIL_RESULT_SUCCESS) {
        fprintf(stderr, "%s: got %d (%s)\n", what, (int)got, histencil_last_error());
        failures += 1;
    }
}

static void expect(HistencilResult got, HistencilResult want, const char *words, const char *what) {
    const char *message = histencil_last_error();
    calls += 1;
    if (got != want || message == NULL || strstr(message, words) == NULL) {
        fprintf(stderr, "%s: got %d (%s), want %d saying `%s`\n", what, (int)got,
                message ? message : "(null)", (int)want, words);
        failures += 1;
    }
}

int main(void) {
    HistencilDeviceDesc device;
    HistencilLightingDesc desc;
    HistencilFrame frame;
    HistencilTargets targets;
    HistencilContext *context = NULL;
    HistencilLighting *lighting = NULL;
    uint8_t reference = 0, write_mask = 0;
    uint32_t in_flight = 0;
    uint32_t version = histencil_version();

    if ((version >> 22) != HISTENCIL_VERSION_MAJOR) {
        fprintf(stderr, "library major version %u, header %d\n", version >> 22, HISTENCIL_VERSION_MAJOR);
        return 1;
    }
    if (strcmp(histencil_last_error(), "") != 0) {
        fprintf(stderr, "a last error before any call\n");
        return 1;
    }
    memset(&device, 0, sizeof device);
    memset(&desc, 0, sizeof desc);
    memset(&frame, 0, sizeof frame);
    memset(&targets, 0, sizeof targets);

    expect(histencil_context_create(NULL, &context), HISTENCIL_RESULT_INVALID_ARGUMENT, "desc is null", "context_create(NULL)");
    expect(histencil_context_create(&device, &context), HISTENCIL_RESULT_INVALID_ARGUMENT, "HistencilDeviceDesc.size is 0", "context_create(size 0)");
    device.size = sizeof device;
    expect(histencil_context_create(&device, NULL), HISTENCIL_RESULT_INVALID_ARGUMENT, "out pointer", "context_create(out NULL)");
    expect(histencil_context_create(&device, &context), HISTENCIL_RESULT_INVALID_ARGUMENT, "instance is VK_NULL_HANDLE", "context_create(null handles)");
    expect(histencil_context_destroy(NULL), HISTENCIL_RESULT_INVALID_ARGUMENT, "context is null", "context_destroy(NULL)");

    desc.size = sizeof desc;
    expect(histencil_lighting_create(NULL, &desc, &lighting), HISTENCIL_RESULT_INVALID_ARGUMENT, "context is null", "lighting_create(NULL)");
    /* A pointer that is no handle of histencil's is refused, never dereferenced. */
    context = (HistencilContext *)&device;
    expect(histencil_lighting_create(context, &desc, &lighting), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Context handle", "lighting_create(foreign)");
    expect(histencil_context_destroy(context), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Context handle", "context_destroy(foreign)");
    /* The hazard check's calls, on the same foreign pointer and on null. */
    {
        VkCommandBuffer none = VK_NULL_HANDLE;
        uint32_t found = 0;
        expect(histencil_context_check_hazards(NULL), HISTENCIL_RESULT_INVALID_ARGUMENT, "context is null", "context_check_hazards(NULL)");
        expect(histencil_context_check_hazards(context), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Context handle", "context_check_hazards(foreign)");
        expect(histencil_note_begin(context, none), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Context handle", "note_begin(foreign)");
        expect(histencil_note_submit(context, &none, 1, VK_NULL_HANDLE), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Context handle", "note_submit(foreign)");
        expect(histencil_note_wait(context, VK_NULL_HANDLE), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Context handle", "note_wait(foreign)");
        expect(histencil_context_hazards(context, &found, NULL, 0, NULL), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Context handle", "context_hazards(foreign)");
    }
    lighting = (HistencilLighting *)&desc;
    expect(histencil_lighting_stencil_reference(lighting, "lambert", &reference, &write_mask), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Lighting handle", "stencil_reference");
    expect(histencil_lighting_record(lighting, VK_NULL_HANDLE, &frame, &targets), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Lighting handle", "record");
    expect(histencil_lighting_slot_finished(lighting, 0), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Lighting handle", "slot_finished");
    expect(histencil_lighting_in_flight(lighting, &in_flight), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Lighting handle", "in_flight");
    expect(histencil_lighting_step_timings(lighting, 0, NULL, &in_flight), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Lighting handle", "step_timings");
    expect(histencil_lighting_resize(lighting, 64, 64), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Lighting handle", "resize");
    expect(histencil_lighting_destroy(lighting), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Lighting handle", "lighting_destroy(foreign)");
    expect(histencil_lighting_destroy(NULL), HISTENCIL_RESULT_INVALID_ARGUMENT, "lighting is null", "lighting_destroy(NULL)");
    {
        HistencilShaders *shaders = NULL;
        expect(histencil_shaders_compile(NULL, "examples/brdfs", NULL, &shaders), HISTENCIL_RESULT_INVALID_ARGUMENT, "context is null", "shaders_compile(NULL)");
        expect(histencil_shaders_load(NULL, "shaders.bin", &shaders), HISTENCIL_RESULT_INVALID_ARGUMENT, "context is null", "shaders_load(NULL)");
        expect(histencil_shaders_destroy((HistencilShaders *)&device), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Shaders handle", "shaders_destroy(foreign)");
        expect(histencil_shaders_write_includes(NULL, "out"), HISTENCIL_RESULT_INVALID_ARGUMENT, "shaders is null", "shaders_write_includes(NULL)");
        {
            HistencilLightmaps *lightmaps = NULL;
            HistencilLightmapsDesc lightmaps_desc;
            HistencilLightmapFrame lightmap_frame;
            HistencilImage atlas;
            VkBuffer entities = VK_NULL_HANDLE;
            memset(&lightmaps_desc, 0, sizeof lightmaps_desc);
            memset(&lightmap_frame, 0, sizeof lightmap_frame);
            memset(&atlas, 0, sizeof atlas);
            expect(histencil_lightmaps_create(NULL, &lightmaps_desc, &lightmaps), HISTENCIL_RESULT_INVALID_ARGUMENT, "context is null", "lightmaps_create(NULL)");
            lightmaps = (HistencilLightmaps *)&device;
            expect(histencil_lightmaps_record(lightmaps, VK_NULL_HANDLE, &lightmap_frame, &atlas, NULL), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Lightmaps handle", "lightmaps_record(foreign)");
            expect(histencil_lightmaps_entity_buffer(lightmaps, 0, &entities), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Lightmaps handle", "lightmaps_entity_buffer(foreign)");
            expect(histencil_lightmaps_slot_finished(lightmaps, 0), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live Lightmaps handle", "lightmaps_slot_finished(foreign)");
            expect(histencil_lightmaps_destroy(NULL), HISTENCIL_RESULT_INVALID_ARGUMENT, "lightmaps is null", "lightmaps_destroy(NULL)");
        }
        {
            HistencilLutTables *tables = NULL;
            HistencilMaterial material;
            memset(&material, 0, sizeof material);
            expect(histencil_lut_tables_create(NULL, NULL, &material, 1, 16, &tables), HISTENCIL_RESULT_INVALID_ARGUMENT, "context is null", "lut_tables_create(NULL)");
            expect(histencil_lighting_set_lut_tables(NULL, tables), HISTENCIL_RESULT_INVALID_ARGUMENT, "lighting is null", "lighting_set_lut_tables(NULL)");
            expect(histencil_lut_tables_destroy((HistencilLutTables *)&device), HISTENCIL_RESULT_INVALID_ARGUMENT, "not a live LutTables handle", "lut_tables_destroy(foreign)");
        }
        expect(histencil_device_suits(NULL, VK_NULL_HANDLE, VK_NULL_HANDLE, 0, &in_flight), HISTENCIL_RESULT_INVALID_ARGUMENT, "get_instance_proc_addr is null", "device_suits(NULL)");
    }

    /* What an engine writes its G-buffer and device with. */
    {
        VkFormat formats[HISTENCIL_GBUFFER_IMAGES];
        HistencilBrdfParam rho;
        float packed[4];
        uint32_t model = 99;
        VkPhysicalDeviceFeatures features;
        VkPhysicalDeviceVulkan13Features features13;
        expect(histencil_gbuffer_formats(NULL), HISTENCIL_RESULT_INVALID_ARGUMENT, "formats is null", "gbuffer_formats(NULL)");
        expect_ok(histencil_gbuffer_formats(formats), "gbuffer_formats");
        if (formats[0] != VK_FORMAT_R16G16B16A16_SFLOAT) {
            fprintf(stderr, "G-buffer image 0 is format %d\n", (int)formats[0]);
            failures += 1;
        }
        expect(histencil_brdf_encode(NULL, "ggx", NULL, 0, packed, &model), HISTENCIL_RESULT_BAD_SETUP, "ggx", "brdf_encode(ggx, no params)");
        expect(histencil_brdf_encode(NULL, "velvet", NULL, 0, packed, &model), HISTENCIL_RESULT_BAD_SETUP, "velvet", "brdf_encode(velvet)");
        expect(histencil_brdf_encode(NULL, "lambert", NULL, 1, packed, &model), HISTENCIL_RESULT_INVALID_ARGUMENT, "params is null", "brdf_encode(NULL params)");
        rho.name = "rho";
        rho.value = 0.8;
        expect_ok(histencil_brdf_encode(NULL, "lambert", &rho, 1, packed, &model), "brdf_encode(lambert)");
        if (model != 0 || packed[0] != 0.8f) {
            fprintf(stderr, "lambert encodes as id %u, %f\n", model, (double)packed[0]);
            failures += 1;
        }
        {
            /* Rows a decode hook reads by material index: written, and refused where they cannot be. */
            HistencilMaterial material;
            unsigned char rows[2 * HISTENCIL_MATERIAL_ROW_BYTES];
            uint32_t id = 99;
            material.brdf_name = "lambert";
            material.param_count = 1;
            material.params = &rho;
            expect(histencil_material_rows_write(NULL, &material, 1, NULL, sizeof rows), HISTENCIL_RESULT_INVALID_ARGUMENT, "rows is null", "material_rows_write(NULL rows)");
            expect(histencil_material_rows_write(NULL, &material, 1, rows, 8), HISTENCIL_RESULT_INVALID_ARGUMENT, "rows_size", "material_rows_write(short)");
            expect(histencil_material_rows_write(NULL, &material, 0, rows, sizeof rows), HISTENCIL_RESULT_INVALID_ARGUMENT, "material_count is 0", "material_rows_write(none)");
            expect_ok(histencil_material_rows_write(NULL, &material, 1, rows, sizeof rows), "material_rows_write(lambert)");
            memcpy(&id, rows + 16, sizeof id);
            if (id != model) {
                fprintf(stderr, "lambert's row holds id %u\n", id);
                failures += 1;
            }
            expect(histencil_lighting_check_materials(NULL, &material, 1), HISTENCIL_RESULT_INVALID_ARGUMENT, "lighting is null", "lighting_check_materials(NULL)");
        }
        memset(&features, 0, sizeof features);
        memset(&features13, 0, sizeof features13);
        expect(histencil_device_features(NULL, &features13), HISTENCIL_RESULT_INVALID_ARGUMENT, "null", "device_features(NULL)");
        expect_ok(histencil_device_features(&features, &features13), "device_features");
        if (!features13.synchronization2 || !features13.dynamicRendering || !features.depthClamp) {
            fprintf(stderr, "device_features left a needed feature off\n");
            failures += 1;
        }
    }

    if (failures > 0) {
        fprintf(stderr, "c99: %d of %d calls not as the header says\n", failures, calls);
        return 1;
    }
    printf("c99: %d calls, every one answered as the header says\n", calls);
    return 0;
}
